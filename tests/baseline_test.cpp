// The baselines of bench/baseline/ give the standard tier's output bit for bit, so that
// timing them against the kernels compares the same work.
#include "baseline.h"

#include <gtest/gtest.h>

#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;

TEST(Baseline, ImagesEqualTheStandardTierBitForBit) {
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 300; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 8));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (double sigma : {0.0, 2.0, 7.5}) {
    for (bool pattern : {true, false}) {
      SCOPED_TRACE("sigma " + std::to_string(sigma) + (pattern ? ", pattern noise" : ""));
      const SceneBatch batch = test::batch_of(scenes, 0xfffffffffull);  // indices cross 2^32
      Plan plan;
      plan.features = false;
      plan.metal = false;
      plan.model.seed = 0x123456789abcull;
      plan.model.pixel_sigma = sigma;
      plan.model.pattern_noise = pattern;
      BatchOutput kernel, loop;
      cl->run(batch, plan, kernel);
      prepare_output(loop, catalogue(), plan, batch.size());
      baseline::render_images(catalogue(), assets(), batch, plan.model, loop);
      for (size_t k = 0; k < kernel.views.size(); ++k) {
        ASSERT_FALSE(kernel.views[k].empty());
        size_t differ = 0;
        for (size_t p = 0; p < kernel.views[k].pixels.size(); ++p)
          differ += kernel.views[k].pixels[p] != loop.views[k].pixels[p];
        EXPECT_EQ(differ, 0u) << kernel.views[k].name;
      }
    }
  }
}

TEST(Baseline, RefusesWhatItDoesNotModel) {
  SceneBatch batch = test::batch_of({test::random_scenario(catalogue(), 1)});
  Plan plan;
  BatchOutput out;
  prepare_output(out, catalogue(), plan, 1);
  ModelSettings m;
  m.jitter = 1;
  EXPECT_THROW(baseline::render_images(catalogue(), assets(), batch, m, out), std::invalid_argument);
}

}  // namespace
}  // namespace portalsim
