// The baselines of bench/baseline/ give the standard tier's output bit for bit, so that
// timing them against the kernels compares the same work.
#include "baseline.h"

#include <gtest/gtest.h>

#include <cstring>

#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;

// The standard tier's plan without the metal zones, which no baseline draws.
Plan baseline_plan(uint64_t seed, bool pattern) {
  Plan plan;
  plan.metal = false;
  plan.model.seed = seed;
  plan.model.pattern_noise = pattern;
  return plan;
}

// The kernels' output of `plan`, and an output laid out for a baseline to fill.
struct Outputs {
  BatchOutput kernel, loop;
};
Outputs run_kernels(Backend& cl, const SceneBatch& batch, const Plan& plan) {
  Outputs o;
  cl.run(batch, plan, o.kernel);
  prepare_output(o.loop, catalogue(), plan, batch.size());
  return o;
}

TEST(Baseline, ImagesEqualTheStandardTierBitForBit) {
  const std::vector<Scenario> scenes = test::coverage(catalogue(), 300, 8, false);
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (double sigma : {0.0, 2.0, 7.5}) {
    for (bool pattern : {true, false}) {
      SCOPED_TRACE("sigma " + std::to_string(sigma) + (pattern ? ", pattern noise" : ""));
      const SceneBatch batch = test::batch_of(scenes, 0xfffffffffull);  // indices cross 2^32
      Plan plan = baseline_plan(0x123456789abcull, pattern);
      plan.features = false;
      plan.model.pixel_sigma = sigma;
      auto [kernel, loop] = run_kernels(*cl, batch, plan);
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

TEST(Baseline, FeaturesEqualTheStandardTierSparsePathBitForBit) {
  const std::vector<Scenario> scenes = test::coverage(catalogue(), 400, 8, false);
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (int block : {10, 7}) {
    for (bool pattern : {true, false}) {
      SCOPED_TRACE("block " + std::to_string(block) + (pattern ? ", pattern noise" : ""));
      const SceneBatch batch = test::batch_of(scenes, 0xfffffff00ull);
      Plan plan = baseline_plan(0x9e3779b97f4aull, pattern);
      plan.images = 0;
      plan.model.block = block;
      auto [kernel, loop] = run_kernels(*cl, batch, plan);
      const baseline::SparseFeatures features(catalogue(), assets(), plan.model);
      features.run(batch, loop);
      ASSERT_EQ(kernel.features.size(), loop.features.size());
      ASSERT_FALSE(kernel.features.empty());
      size_t differ = 0, changed = 0;
      for (size_t f = 0; f < kernel.features.size(); ++f) {
        differ += std::memcmp(&kernel.features[f], &loop.features[f], sizeof(float)) != 0;
        changed += kernel.features[f] != kernel.features[f % kernel.layout.image_features()];
      }
      EXPECT_EQ(differ, 0u);
      EXPECT_GT(changed, kernel.features.size() / 100);  // the scenarios differ from each other
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
  EXPECT_THROW(baseline::SparseFeatures(catalogue(), assets(), m), std::invalid_argument);
  m.jitter = 0;
  m.pixel_sigma = 2;
  EXPECT_THROW(baseline::SparseFeatures(catalogue(), assets(), m), std::invalid_argument);
}

}  // namespace
}  // namespace portalsim
