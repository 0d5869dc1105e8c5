// Parity checks of the physics model's drawn knobs that several suites share, and their
// set-ups: the kernels' images and the features-only path against the fp64 reference.
// Apart from support.h, which the tests' precompiled header holds, as these need compare.h.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "backend/backend.h"
#include "backend/compare.h"
#include "plan/knobs.h"
#include "support.h"

namespace portalsim::test {

// The physics model's plan (seed `seed`) without sensor noise, in `tier`, fused or as the
// chain of stage kernels, with --clothing `clothing`.
inline Plan clothed_plan(uint64_t seed, const std::string& clothing, Tier tier, bool fused) {
  Plan plan = physics_plan(seed);
  plan.model.netd = 0;
  plan.model.ir_netd = 0;
  plan.fidelity = tier_fidelity(tier);
  plan.fidelity.fused = fused;
  set_knob(plan, *find_knob("clothing"), clothing, "--clothing");
  return plan;
}

// A batch of kImageScenes random crowds (random_scenario from k = `from`, up to 6 objects)
// indexed from `first`, and the default catalogue's reference and OpenCL backends to run it.
struct ParityRun {
  SceneBatch batch;
  std::unique_ptr<Backend> ref, ocl;
};
inline ParityRun parity_run(uint64_t from, uint64_t first) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < kImageScenes; ++k) scenes.push_back(random_scenario(catalogue(), from + k, 6));
  return {batch_of(scenes, first), make_reference_backend(catalogue(), assets()),
          make_opencl_backend(catalogue(), assets(), runtime())};
}

// The kernels' MMW and IR images against the reference's within each camera's parity
// (expect_camera_parity), for plan_of(tier, fused) in the standard and exact tiers, fused
// and as the chain of stage kernels, alone and with the illumination and worn time drawn
// too. The drawn knob reaches the images: the plan with `plain` applied (the knob at its
// plain value) gives others.
inline void expect_drawn_images_parity(Backend& ref, Backend& ocl, const SceneBatch& batch,
                                       const std::function<Plan(Tier, bool)>& plan_of,
                                       const std::function<void(Plan&)>& plain) {
  for (Tier tier : {Tier::standard, Tier::exact})
    for (bool fused : {true, false})
      for (bool scene : {false, true}) {
        SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain") +
                     (scene ? ", illumination and worn time drawn" : ""));
        Plan plan = plan_of(tier, fused);
        if (scene) {
          set_knob(plan, *find_knob("illumination"), "280..310", "--illumination");
          set_knob(plan, *find_knob("worn_minutes"), "0..60", "--worn-minutes");
        }
        BatchOutput r, k;
        ref.run(batch, plan, r);
        ocl.run(batch, plan, k);
        const OutputDiff d = compare_outputs(k, r);
        EXPECT_GT(d.of(Camera::mmw).pixels, 0u);
        EXPECT_GT(d.of(Camera::ir).pixels, 0u);
        expect_camera_parity(d.of(Camera::mmw));
        expect_camera_parity(d.of(Camera::ir));
        BatchOutput other;
        Plan plain_plan = plan;
        plain(plain_plan);
        ocl.run(batch, plain_plan, other);
        for (size_t v = 0; v < k.views.size(); ++v) EXPECT_NE(k.views[v].pixels, other.views[v].pixels) << v;
      }
}

// The features of `plan` (a fast-tier physics plan) without its images, in a window no
// body leaves (250 to 340 K), against the reference's images run: the physics_raw_features
// path in `variant` ("untabulated" or "tabulated"), within the tolerance table's fast-tier
// bound. `features` gets the features-only plan and `k` its output.
inline void expect_raw_features_parity(Backend& ref, Backend& ocl, const SceneBatch& batch, Plan plan,
                                       const std::string& variant, Plan& features, BatchOutput& k) {
  plan.model.window_lo = 250;
  plan.model.window_hi = 340;
  features = plan;
  features.images = 0;
  const std::vector<std::string> paths = ocl.paths(features);
  ASSERT_NE(std::find(paths.begin(), paths.end(), "features: physics_raw_features (" + variant + ")"), paths.end())
      << testing::PrintToString(paths);
  BatchOutput r;
  ref.run(batch, plan, r);
  ocl.run(batch, features, k);
  const OutputDiff d = compare_outputs(k, r);
  ASSERT_TRUE(d.features_only);
  EXPECT_EQ(check_tolerance(d, model_tolerance(Model::physics, Tier::fast)), "");
}

}  // namespace portalsim::test
