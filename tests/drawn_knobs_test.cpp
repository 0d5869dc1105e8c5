// Knobs drawn per scenario (A..B, plan.h ModelSettings::drawn): each scenario's value from
// the counter generator, the same on both backends and in every batch, recorded per row,
// and a fixed value (A..A) keeping today's bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "backend/compare.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "sink/h5_file.h"
#include "support.h"

namespace portalsim {
namespace {

namespace fs = std::filesystem;
// The image tests' scenarios; under the sanitizers (support.h, kSanitized), whose fp64
// reference loops run several times slower, a quarter of them.
const size_t kScenes = test::kSanitized ? 10 : 40;
using test::assets;
using test::catalogue;

Plan metal_plan(Model model, uint64_t seed, const std::string& metal_noise) {
  Plan plan;
  plan.images = 0;
  plan.features = false;
  plan.model.model = model;
  plan.model.seed = seed;
  set_knob(plan, *find_knob("metal_noise"), metal_noise, "--metal-noise");
  return plan;
}

std::vector<uint8_t> metal(Backend& b, const SceneBatch& batch, const Plan& plan) {
  BatchOutput out;
  b.run(batch, plan, out);
  return out.metal;
}

TEST(DrawnKnobs, MetalNoiseDrawnPerScenarioIsTheReferencesOnBothModels) {
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 2000; ++k) scenes.push_back(test::random_scenario(catalogue(), k));
  const SceneBatch batch = test::batch_of(scenes, 5000);
  for (Model model : {Model::thesis, Model::physics}) {
    const Plan drawn = metal_plan(model, 77, "0..12");
    const std::vector<uint8_t> a = metal(*ref, batch, drawn), b = metal(*ocl, batch, drawn);
    ASSERT_EQ(a.size(), b.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
    EXPECT_EQ(differ, 0u) << model_name(model);
    // A range of one value is that value, to the byte; the range's ends on their own too.
    for (const auto& [range, fixed] : {std::pair{"0..0", "0"}, {"7..7", "7"}, {"199..199", "199"}})
      for (Backend* be : {ref.get(), ocl.get()})
        EXPECT_EQ(metal(*be, batch, metal_plan(model, 77, range)), metal(*be, batch, metal_plan(model, 77, fixed)))
            << model_name(model) << " " << range << " on " << be->name();
    // The drawn noise moves zones a fixed noise leaves alone, and differs from either end.
    EXPECT_NE(a, metal(*ref, batch, metal_plan(model, 77, "0")));
    EXPECT_NE(a, metal(*ref, batch, metal_plan(model, 77, "12")));
  }
  // Every value of the range is drawn, none outside it, the same for a scenario however asked.
  const ModelSettings m = metal_plan(Model::thesis, 77, "3..9").model;
  std::set<int> seen;
  for (uint64_t i = 0; i < 2000; ++i) {
    const int v = metal_noise_at(m, i);
    EXPECT_GE(v, 3);
    EXPECT_LE(v, 9);
    EXPECT_EQ(drawn_knob_at(m, PS_DRAWN_METAL_NOISE, i), v);
    seen.insert(v);
  }
  EXPECT_EQ(seen.size(), 7u);
}

// Image i's mean squared difference between a and b (a noisy image against its noise-free one).
double mean_square_difference(const ViewImages& a, const ViewImages& b, size_t i) {
  double ms = 0;
  for (size_t p = 0; p < a.pixels_per_image(); ++p) {
    const double e = double(a.of(i)[p]) - double(b.of(i)[p]);
    ms += e * e;
  }
  return ms / double(a.pixels_per_image());
}

// The IR NETD drawn per scenario: the kernels' images are the reference's within the IR
// parity test's stated tolerance (IrPhysics.KernelsMatchTheReferenceInEveryTier), on the
// fused path and the chain of stage kernels; a scenario's noise is its own draw's.
TEST(DrawnKnobs, IrNetdDrawnPerScenarioIsTheReferencesOnEveryPath) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < kScenes; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes, 300);
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto plan_of = [](const std::string& ir_netd, bool fused, Tier tier) {
    Plan plan = test::physics_plan(31);
    plan.fidelity = tier_fidelity(tier);
    plan.fidelity.fused = fused;
    set_knob(plan, *find_knob("ir_netd"), ir_netd, "--ir-netd");
    return plan;
  };
  const size_t ir = static_cast<size_t>(catalogue().sensor_index("ir"));
  for (Tier tier : {Tier::standard, Tier::exact})
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      const Plan drawn = plan_of("0..0.6", fused, tier);
      BatchOutput r, k;
      ref->run(batch, drawn, r);
      ocl->run(batch, drawn, k);
      const OutputDiff d = compare_outputs(k, r);
      EXPECT_GT(d.ir.pixels, 0u);
      test::expect_camera_parity(d.ir);
      // A range of one value is that value, to the byte.
      BatchOutput one, fixed;
      ocl->run(batch, plan_of("0.2..0.2", fused, tier), one);
      ocl->run(batch, plan_of("0.2", fused, tier), fixed);
      EXPECT_EQ(one.views[ir].pixels, fixed.views[ir].pixels);
      // Each scenario's image is noisier where its draw is larger: against the noise-free
      // image, the mean squared difference follows the drawn NETD.
      BatchOutput quiet;
      ocl->run(batch, plan_of("0", fused, tier), quiet);
      const ModelSettings m = drawn.model;
      double low = 0, high = 0;
      int nl = 0, nh = 0;
      for (size_t i = 0; i < batch.size(); ++i) {
        const double ms = mean_square_difference(k.views[ir], quiet.views[ir], i);
        const double netd = ir_netd_at(m, batch.first_index + i);
        if (netd < 0.15) {
          low += ms;
          ++nl;
        } else if (netd > 0.45) {
          high += ms;
          ++nh;
        }
      }
      ASSERT_GT(nl, 0);
      ASSERT_GT(nh, 0);
      EXPECT_GT(high / nh, 4 * (low / nl));
    }
}

// The MMW camera's NETD and frames drawn per scenario (netd_at, frames_at): the kernels'
// MMW images are the reference's within the MMW camera's parity tolerance
// (Physics.KernelsMatchTheReferenceInEveryTier: 1 gray level, at most 0.5% off by one) in
// every tier (the fast tier's frames as one draw, Irwin-Hall), fused and as the chain of
// stage kernels; each scenario's noise is its own draw's.
TEST(DrawnKnobs, MmwNetdAndFramesDrawnPerScenarioAreTheReferencesOnEveryPath) {
  std::vector<Scenario> scenes;  // all 40 under the sanitizers too: both noise groups need members
  for (size_t k = 0; k < 40; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes, 700);
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto plan_of = [](const std::string& netd, const std::string& frames, bool fused, Tier tier) {
    Plan plan = test::physics_plan(41);
    plan.fidelity = tier_fidelity(tier);
    plan.fidelity.fused = fused;
    set_knob(plan, *find_knob("netd"), netd, "--netd");
    set_knob(plan, *find_knob("frames"), frames, "--frames");
    return plan;
  };
  for (Tier tier : {Tier::standard, Tier::exact, Tier::fast})
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      const Plan drawn = plan_of("0.2..2", "1..9", fused, tier);
      BatchOutput r, k;
      ref->run(batch, drawn, r);
      ocl->run(batch, drawn, k);
      const OutputDiff d = compare_outputs(k, r);
      EXPECT_GT(d.mmw.pixels, 0u);
      test::expect_camera_parity(d.mmw);
      // A range of one value is that value, to the byte.
      BatchOutput one, fixed;
      ocl->run(batch, plan_of("1.5..1.5", "4..4", fused, tier), one);
      ocl->run(batch, plan_of("1.5", "4", fused, tier), fixed);
      for (size_t v = 0; v < one.views.size(); ++v) EXPECT_EQ(one.views[v].pixels, fixed.views[v].pixels) << v;
      // Each scenario's image is as noisy as its draw: against the noise-free image, the
      // mean squared difference follows NETD^2 / frames.
      BatchOutput quiet;
      ocl->run(batch, plan_of("0", "1", fused, tier), quiet);
      const size_t upper = static_cast<size_t>(catalogue().sensor_index("upper"));
      double low = 0, high = 0;
      int nl = 0, nh = 0;
      for (size_t i = 0; i < batch.size(); ++i) {
        const double ms = mean_square_difference(k.views[upper], quiet.views[upper], i);
        const double sd = netd_at(drawn.model, batch.first_index + i) /
                          std::sqrt(double(frames_at(drawn.model, batch.first_index + i)));
        if (sd < 0.3) {
          low += ms;
          ++nl;
        } else if (sd > 0.9) {
          high += ms;
          ++nh;
        }
      }
      ASSERT_GT(nl, 0);
      ASSERT_GT(nh, 0);
      EXPECT_GT(high / nh, 4 * (low / nl));
    }
  // Every frame count of the range is drawn, none outside it; the NETD stays in its range.
  const ModelSettings m = plan_of("0.2..2", "1..9", true, Tier::standard).model;
  std::set<int> seen;
  for (uint64_t i = 0; i < 2000; ++i) {
    seen.insert(frames_at(m, i));
    EXPECT_GE(netd_at(m, i), 0.2);
    EXPECT_LT(netd_at(m, i), 2.0);
    EXPECT_EQ(drawn_knob_at(m, PS_DRAWN_FRAMES, i), frames_at(m, i));
  }
  EXPECT_EQ(seen, (std::set<int>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

// The features-only path of the physics model (physics_raw_features) draws the NETD per
// feature, scaled by the scenario's NETD / sqrt(frames) under the block-mean model: with
// the same draws, a scenario's noise is its draw times the noise of NETD 1 over one frame.
// Tolerance: 0.01 gray levels, for fp32 features near 128 (rounding about 1e-5 of them)
// summed over up to a hundred noise terms; the smallest drawn noise is 100 times that.
TEST(DrawnKnobs, MmwNetdAndFramesDrawnPerScenarioScaleTheFeatureNoise) {
  const SceneBatch batch = test::batch_of(test::coverage(catalogue(), 200, 6), 900);
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto plan_of = [](const std::string& netd, const std::string& frames) {
    Plan plan = test::physics_plan(43);
    plan.fidelity = tier_fidelity(Tier::fast);
    plan.images = 0;
    plan.metal = false;
    set_knob(plan, *find_knob("netd"), netd, "--netd");
    set_knob(plan, *find_knob("frames"), frames, "--frames");
    return plan;
  };
  const Plan drawn = plan_of("0.5..3", "1..9");
  ASSERT_EQ(test::features_path(*ocl, drawn), "physics_raw_features");
  BatchOutput d, unit, quiet;
  ocl->run(batch, drawn, d);
  ocl->run(batch, plan_of("1", "1"), unit);
  ocl->run(batch, plan_of("0", "1"), quiet);
  const size_t row = d.layout.image_features();
  ASSERT_EQ(d.features.size(), unit.features.size());
  size_t checked = 0, off = 0;
  double worst = 0;
  for (size_t i = 0; i < batch.size(); ++i) {
    const uint64_t index = batch.first_index + i;
    const double s = netd_at(drawn.model, index) / std::sqrt(double(frames_at(drawn.model, index)));
    for (size_t c = 0; c < row; ++c) {
      const size_t at = i * row + c;
      const double q = quiet.features[at], u = unit.features[at], v = d.features[at];
      if (q < 20 || q > 235 || u <= 0 || u >= 255 || v <= 0 || v >= 255) continue;  // the window may clamp
      const double e = std::abs((v - q) - s * (u - q));
      worst = std::max(worst, e);
      off += e > 0.01;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000u);
  EXPECT_EQ(off, 0u) << "worst " << worst;
}

// The illumination and the worn time drawn per scenario (illumination_at,
// worn_minutes_at): the kernels' MMW and IR images are the reference's within each camera's
// parity tolerance (1 gray level or index, at most 0.5% off by one), fused and as the chain
// of stage kernels, and the features-only path's features within the tolerance table's
// (it leaves its tables for the raw grid then); each scenario shows its own draw.
TEST(DrawnKnobs, IlluminationAndWornTimeDrawnPerScenarioAreTheReferencesOnEveryPath) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < kScenes; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes, 1100);
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto plan_of = [](const std::string& ill, const std::string& worn, bool fused, Tier tier) {
    Plan plan = test::physics_plan(47);
    plan.model.netd = 0;
    plan.model.ir_netd = 0;
    plan.fidelity = tier_fidelity(tier);
    plan.fidelity.fused = fused;
    set_knob(plan, *find_knob("illumination"), ill, "--illumination");
    set_knob(plan, *find_knob("worn_minutes"), worn, "--worn-minutes");
    return plan;
  };
  const size_t upper = static_cast<size_t>(catalogue().sensor_index("upper"));
  for (Tier tier : {Tier::standard, Tier::exact})
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      const Plan drawn = plan_of("280..310", "0..60", fused, tier);
      BatchOutput r, k;
      ref->run(batch, drawn, r);
      ocl->run(batch, drawn, k);
      const OutputDiff d = compare_outputs(k, r);
      EXPECT_GT(d.mmw.pixels, 0u);
      EXPECT_GT(d.ir.pixels, 0u);
      test::expect_camera_parity(d.mmw);
      test::expect_camera_parity(d.ir);
      // A range of one value is that value, to the byte.
      BatchOutput one, fixed;
      ocl->run(batch, plan_of("300..300", "20..20", fused, tier), one);
      ocl->run(batch, plan_of("300", "20", fused, tier), fixed);
      for (size_t v = 0; v < one.views.size(); ++v) EXPECT_EQ(one.views[v].pixels, fixed.views[v].pixels) << v;
      // The body reflects the illumination: a scenario's MMW view is brighter the warmer its draw.
      double warm = 0, cold = 0;
      int nw = 0, nc = 0;
      for (size_t i = 0; i < batch.size(); ++i) {
        const ViewImages& a = k.views[upper];
        double mean = 0;
        for (size_t p = 0; p < a.pixels_per_image(); ++p) mean += a.of(i)[p];
        mean /= double(a.pixels_per_image());
        const double ill = illumination_at(drawn.model, batch.first_index + i);
        if (ill > 302) warm += mean, ++nw;
        if (ill < 288) cold += mean, ++nc;
      }
      ASSERT_GT(nw, 0);
      ASSERT_GT(nc, 0);
      EXPECT_GT(warm / nw, cold / nc + 10);
    }
  // Features only: the raw-grid path, its untabulated variant, which leaves the pixels'
  // clipping out: a window no draw's body reaches.
  Plan with_images = plan_of("280..310", "0..60", true, Tier::fast);
  with_images.model.window_lo = 250;
  with_images.model.window_hi = 340;
  Plan features = with_images;
  features.images = 0;
  ASSERT_EQ(test::features_path(*ocl, features), "physics_raw_features");
  const std::vector<std::string> paths = ocl->paths(features);
  EXPECT_NE(std::find(paths.begin(), paths.end(), "features: physics_raw_features (untabulated)"), paths.end());
  BatchOutput r, k;
  ref->run(batch, with_images, r);
  ocl->run(batch, features, k);
  const OutputDiff d = compare_outputs(k, r);
  ASSERT_TRUE(d.features_only);
  EXPECT_EQ(check_tolerance(d, model_tolerance(Model::physics, Tier::fast)), "");
  // Each knob's draws stay in its range.
  for (uint64_t i = 0; i < 2000; ++i) {
    EXPECT_GE(illumination_at(features.model, i), 280.0);
    EXPECT_LT(illumination_at(features.model, i), 310.0);
    EXPECT_GE(worn_minutes_at(features.model, i), 0.0);
    EXPECT_LT(worn_minutes_at(features.model, i), 60.0);
  }
}

// The thesis model's pixel noise drawn per scenario (pixel_noise_at): the kernels' images
// are the reference's within the thesis tolerance table's, in every tier, on the fused
// render and the chain of stage kernels, and so are the features-only path's features under
// the per-pixel noise model; the block-mean features scale their noise by the scenario's
// sigma (the same draws: a scenario's noise is its sigma times sigma 1's).
TEST(DrawnKnobs, PixelNoiseDrawnPerScenarioIsTheReferencesOnEveryPath) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < kScenes; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes, 1300);
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto plan_of = [](const std::string& sigma, bool fused, Tier tier) {
    Plan plan;
    plan.model.seed = 53;
    plan.fidelity = tier_fidelity(tier);
    plan.fidelity.fused = fused;
    set_knob(plan, *find_knob("pixel_noise"), sigma, "--pixel-noise");
    return plan;
  };
  const size_t upper = static_cast<size_t>(catalogue().sensor_index("upper"));
  for (Tier tier : {Tier::standard, Tier::exact, Tier::fast})
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      const Plan drawn = plan_of("0..6", fused, tier);
      BatchOutput r, k;
      ref->run(batch, drawn, r);
      ocl->run(batch, drawn, k);
      EXPECT_EQ(check_tolerance(compare_outputs(k, r), model_tolerance(Model::thesis, tier)), "");
      // A range of one value is that value, to the byte.
      BatchOutput one, fixed;
      ocl->run(batch, plan_of("2.5..2.5", fused, tier), one);
      ocl->run(batch, plan_of("2.5", fused, tier), fixed);
      for (size_t v = 0; v < one.views.size(); ++v) EXPECT_EQ(one.views[v].pixels, fixed.views[v].pixels) << v;
      // Each scenario's image is as noisy as its draw.
      BatchOutput quiet;
      ocl->run(batch, plan_of("0", fused, tier), quiet);
      double low = 0, high = 0;
      int nl = 0, nh = 0;
      for (size_t i = 0; i < batch.size(); ++i) {
        const double ms = mean_square_difference(k.views[upper], quiet.views[upper], i);
        const double sigma = pixel_noise_at(drawn.model, batch.first_index + i);
        if (sigma < 1.5) low += ms, ++nl;
        if (sigma > 4.5) high += ms, ++nh;
      }
      ASSERT_GT(nl, 0);
      ASSERT_GT(nh, 0);
      EXPECT_GT(high / nh, 4 * (low / nl));
    }
  // Features only under the per-pixel noise model (fp32 and fp64): the kernels' features are
  // the reference's (from its images) within the features-only bounds.
  for (Tier tier : {Tier::standard, Tier::exact}) {
    SCOPED_TRACE(std::string(tier_name(tier)) + " features only, per-pixel noise");
    const Plan with_images = plan_of("0..6", true, tier);
    Plan features = with_images;
    features.images = 0;
    ASSERT_TRUE(features.pixel_noise_per_pixel());
    BatchOutput r, k;
    ref->run(batch, with_images, r);
    ocl->run(batch, features, k);
    const OutputDiff d = compare_outputs(k, r);
    ASSERT_TRUE(d.features_only);
    EXPECT_EQ(check_tolerance(d, model_tolerance(Model::thesis, tier)), "");
  }
  // Features only under the block-mean model: each feature's noise is sigma times sigma 1's,
  // within 0.01 gray levels (fp32 features near 128 and one multiply; the smallest drawn
  // noise's sd is over 100 times that), where nothing clips.
  const auto features_of = [&](const std::string& sigma) {
    Plan plan = plan_of(sigma, true, Tier::fast);
    plan.images = 0;
    plan.metal = false;
    return plan;
  };
  const Plan d_plan = features_of("0.5..6");
  ASSERT_FALSE(d_plan.pixel_noise_per_pixel());
  BatchOutput d, unit, quiet;
  ocl->run(batch, d_plan, d);
  ocl->run(batch, features_of("1"), unit);
  ocl->run(batch, features_of("0"), quiet);
  const size_t row = d.layout.image_features();
  size_t checked = 0, off = 0;
  for (size_t i = 0; i < batch.size(); ++i) {
    const double s = pixel_noise_at(d_plan.model, batch.first_index + i);
    for (size_t c = 0; c < row; ++c) {
      const size_t at = i * row + c;
      const double q = quiet.features[at], u = unit.features[at], v = d.features[at];
      if (q < 20 || q > 235 || u <= 0 || u >= 255 || v <= 0 || v >= 255) continue;
      off += std::abs((v - q) - s * (u - q)) > 0.01;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_EQ(off, 0u);
}

// Every drawn knob at the ends of its bounds: a range of one value there is that value to
// the byte, and the whole bounds drawn hold the kernels to the reference within the
// tolerance table's (standard tier) on the model the knob acts in.
TEST(DrawnKnobs, EachKnobAtTheEndsOfItsBoundsIsTheReferences) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < 12; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes, 1500);
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  size_t drawable = 0;
  for (const Knob& knob : knobs()) {
    if (knob.drawn < 0) continue;
    ++drawable;
    const Model model = knob.key == "pixel_noise" ? Model::thesis : Model::physics;
    const auto plan_of = [&](const std::string& value) {
      Plan plan = model == Model::physics ? test::physics_plan(59) : Plan{};
      plan.model.seed = 59;
      // Folds belong to a drawn outfit (--clothing).
      if (knob.key == "clothing_folds") set_knob(plan, *find_knob("clothing"), "random", "--clothing");
      set_knob(plan, knob, value, "--" + knob.key);
      return plan;
    };
    const auto text = [](double v) {
      std::ostringstream o;
      o << v;
      return o.str();
    };
    const std::string lo = text(knob.min), hi = text(knob.max);
    for (const std::string& end : {lo, hi}) {
      SCOPED_TRACE(knob.key + " = " + end);
      BatchOutput one, fixed;
      ocl->run(batch, plan_of(end + ".." + end), one);
      ocl->run(batch, plan_of(end), fixed);
      for (size_t v = 0; v < one.views.size(); ++v) EXPECT_EQ(one.views[v].pixels, fixed.views[v].pixels) << v;
      EXPECT_EQ(one.metal, fixed.metal);
    }
    SCOPED_TRACE(knob.key + " = " + lo + ".." + hi);
    const Plan whole = plan_of(lo + ".." + hi);
    BatchOutput r, k;
    ref->run(batch, whole, r);
    ocl->run(batch, whole, k);
    EXPECT_EQ(check_tolerance(compare_outputs(k, r), model_tolerance(model, Tier::standard)), "");
  }
  // Every number the knob draw stream's elements draw belongs to a knob: one of these, or an
  // end of a range knob whose ends are drawn (the window, its own test below).
  size_t ends = 0, numbers = 0;
  for (const Knob& knob : knobs()) ends += knob.drawn_ends[0] >= 0 ? 2 : 0;
  for (const char* key : kDrawnKnobKeys) numbers += *key != 0;
  EXPECT_EQ(drawable + ends, numbers);
}

// The MMW display window's ends drawn per scenario (--window L1..L2/H1..H2: window_lo_at,
// window_hi_at; kernels/window.cl puts the scenario's ends on the range's low ends before
// the display, the reference shows each scenario through its own window): the kernels' MMW
// images are the reference's within the MMW camera's parity tolerance (1 gray level, at most
// 0.5% off by one) in every tier, fused and as the chain of stage kernels, and at the knob's
// bounds; each scenario's image is the one its window gives when fixed; IR and metal move
// not; the features-only run leaves the tables for the pooled images.
TEST(DrawnKnobs, WindowEndsDrawnPerScenarioAreTheReferencesOnEveryPath) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < kScenes; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes, 1700);
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto plan_of = [](const std::string& window, bool fused, Tier tier) {
    Plan plan = test::physics_plan(61);
    plan.fidelity = tier_fidelity(tier);
    plan.fidelity.fused = fused;
    set_knob(plan, *find_knob("window"), window, "--window");
    return plan;
  };
  const size_t upper = static_cast<size_t>(catalogue().sensor_index("upper"));
  const auto mmw_within = [](const OutputDiff& d) {
    EXPECT_GT(d.mmw.pixels, 0u);
    test::expect_camera_parity(d.mmw);
    EXPECT_EQ(d.metal_exact, 1.0);
  };
  for (Tier tier : {Tier::standard, Tier::exact, Tier::fast})
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      const Plan drawn = plan_of("285..292/300..306", fused, tier);
      BatchOutput r, k;
      ref->run(batch, drawn, r);
      ocl->run(batch, drawn, k);
      mmw_within(compare_outputs(k, r));
      // The IR views and the metal are the fixed window's run's, to the byte.
      BatchOutput fixed;
      ocl->run(batch, plan_of("285..300", fused, tier), fixed);
      EXPECT_EQ(k.metal, fixed.metal);
      for (size_t v = 0; v < k.views.size(); ++v) {
        if (catalogue().sensors[v].camera == Camera::ir) {
          EXPECT_EQ(k.views[v].pixels, fixed.views[v].pixels) << v;
        }
      }
      EXPECT_NE(k.views[upper].pixels, fixed.views[upper].pixels);
    }
  {
    // Ranges of one value are that window, to the byte.
    BatchOutput one, fixed;
    ocl->run(batch, plan_of("290..290/302..302", true, Tier::standard), one);
    ocl->run(batch, plan_of("290..302", true, Tier::standard), fixed);
    for (size_t v = 0; v < one.views.size(); ++v) EXPECT_EQ(one.views[v].pixels, fixed.views[v].pixels) << v;
    EXPECT_EQ(find_knob("window")->get(plan_of("290..290/302..302", true, Tier::standard)), "290..302");
    EXPECT_EQ(find_knob("window")->get(plan_of("285..292/302", true, Tier::standard)), "285..292/302");
  }
  {
    // Each scenario's image is its window's, fixed, on a batch of that scenario alone.
    const Plan drawn = plan_of("280..295/297..320", true, Tier::standard);
    BatchOutput k;
    ocl->run(batch, drawn, k);
    for (size_t i : {size_t{0}, size_t{3}, batch.size() - 1}) {
      const uint64_t index = batch.first_index + i;
      const std::string own =
          std::to_string(window_lo_at(drawn.model, index)) + ".." + std::to_string(window_hi_at(drawn.model, index));
      SCOPED_TRACE("scenario " + std::to_string(index) + ", window " + own);
      BatchOutput alone;
      ocl->run(test::batch_of({scenes[i]}, index), plan_of(own, true, Tier::standard), alone);
      const ViewImages &a = k.views[upper], &b = alone.views[upper];
      int worst = 0;
      for (size_t p = 0; p < a.pixels_per_image(); ++p) worst = std::max(worst, std::abs(a.of(i)[p] - b.of(0)[p]));
      EXPECT_LE(worst, 1);  // the decimal text of the window's ends, rounded at the 6th place
    }
  }
  {
    // The knob's bounds: a window from 0..1 to 999..1000 K, and one as narrow as they allow.
    for (const char* window : {"0..1/999..1000", "0..999/999.5..1000"}) {
      SCOPED_TRACE(window);
      const Plan drawn = plan_of(window, true, Tier::standard);
      BatchOutput r, k;
      ref->run(batch, drawn, r);
      ocl->run(batch, drawn, k);
      mmw_within(compare_outputs(k, r));
    }
  }
  // Features only: the raw-grid path, which applies each scenario's window to its sums in
  // kelvin (tabulated, and untabulated where jitter moves the objects), and leaves the
  // pixels' clipping out: a window no body reaches. Noise-free: the path draws its noise in
  // feature space, the reference per raw pixel.
  for (const double jitter : {0.0, 4.0}) {
    Plan with_images = plan_of("240..250/345..360", true, Tier::fast);
    with_images.model.jitter = jitter;
    with_images.model.netd = 0;
    Plan features = with_images;
    features.images = 0;
    ASSERT_EQ(test::features_path(*ocl, features), "physics_raw_features");
    const std::vector<std::string> paths = ocl->paths(features);
    const std::string variant = jitter > 0 ? "untabulated" : "tabulated";
    EXPECT_NE(std::find(paths.begin(), paths.end(), "features: physics_raw_features (" + variant + ")"), paths.end());
    BatchOutput r, k, fixed;
    ref->run(batch, with_images, r);
    ocl->run(batch, features, k);
    const OutputDiff d = compare_outputs(k, r);
    ASSERT_TRUE(d.features_only);
    EXPECT_EQ(check_tolerance(d, model_tolerance(Model::physics, Tier::fast)), "") << variant;
    Plan fixed_plan = plan_of("240..345", true, Tier::fast);
    fixed_plan.model.jitter = jitter;
    fixed_plan.model.netd = 0;
    fixed_plan.images = 0;
    ocl->run(batch, fixed_plan, fixed);
    EXPECT_NE(k.features, fixed.features) << variant;
  }
  Plan features = plan_of("285..292/300..306", true, Tier::fast);
  // Each end's draws stay in its range.
  for (uint64_t i = 0; i < 2000; ++i) {
    EXPECT_GE(window_lo_at(features.model, i), 285.0);
    EXPECT_LT(window_lo_at(features.model, i), 292.0);
    EXPECT_GE(window_hi_at(features.model, i), 300.0);
    EXPECT_LT(window_hi_at(features.model, i), 306.0);
  }
}

test::Result gen(const test::TempDir& t, std::vector<std::string> args, const fs::path& out) {
  if (std::find(args.begin(), args.end(), "--scenarios") == args.end()) args.insert(args.end(), {"--count", "40"});
  args.insert(args.end(), {"--seed", "9"});
  return test::generate(t, args, out);
}

TEST(DrawnKnobs, EachScenariosDrawIsRecordedAndAFixedRangeKeepsTheBytes) {
  test::TempDir t;
  // A..A is A: the same files, byte for byte (the manifest records "3" both times).
  ASSERT_EQ(gen(t, {"--metal-noise", "3"}, t.w() / "fixed").status, 0);
  ASSERT_EQ(gen(t, {"--metal-noise", "3..3"}, t.w() / "one").status, 0);
  for (const char* f : {"scenarios.csv", "features.arff", "manifest.json"})
    EXPECT_EQ(test::slurp(t.w() / "fixed" / f), test::slurp(t.w() / "one" / f)) << f;
  // Drawn: the same bytes for any batch and thread count; each row's draw recorded.
  const test::Result a = gen(t, {"--metal-noise", "0..8", "--format", "csv,h5", "--batch", "7"}, t.w() / "a");
  ASSERT_EQ(a.status, 0) << test::describe(a);
  ASSERT_EQ(
      gen(t, {"--metal-noise", "0..8", "--format", "csv,h5", "--batch", "40", "--threads", "1"}, t.w() / "b").status,
      0);
  for (const char* f : {"scenarios.csv", "features.csv", "data.h5"})
    EXPECT_EQ(test::slurp(t.w() / "a" / f), test::slurp(t.w() / "b" / f)) << f;
  const auto rows = test::csv_cells(t.w() / "a" / "scenarios.csv");
  ASSERT_EQ(rows.size(), 41u);
  const auto col = std::find(rows[0].begin(), rows[0].end(), "metal_noise");
  ASSERT_NE(col, rows[0].end());
  const size_t c = static_cast<size_t>(col - rows[0].begin());
  const ModelSettings m = metal_plan(Model::thesis, 9, "0..8").model;
  for (size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i][c], std::to_string(metal_noise_at(m, i - 1))) << i;
  // The features' metal zones are the drawn noise's: 3 of them differ from a run at 0.
  EXPECT_NE(test::slurp(t.w() / "a" / "features.csv"), test::slurp(t.w() / "fixed" / "features.csv"));
  bool param = false;
  for (const H5Dataset& d : read_h5_layout((t.w() / "a" / "data.h5").string()).datasets)
    param = param || (d.name == "param_metal_noise" && d.type == TensorType::f64);
  EXPECT_TRUE(param);
  EXPECT_NE(test::slurp(t.w() / "a" / "croissant.json").find("the value the knob metal_noise was drawn"),
            std::string::npos);
  // The list re-runs: its metal_noise column is read as the record it is.
  ASSERT_EQ(
      gen(t, {"--metal-noise", "0..8", "--scenarios", (t.w() / "a" / "scenarios.csv").string()}, t.w() / "c").status,
      0);
  EXPECT_EQ(test::slurp(t.w() / "a" / "scenarios.csv"), test::slurp(t.w() / "c" / "scenarios.csv"));
}

// The window's drawn ends: a column each in scenarios.csv (the run's window_lo_at and
// window_hi_at), float64 datasets in data.h5, the manifest's window as given.
TEST(DrawnKnobs, WindowEndsDrawnAreRecorded) {
  test::TempDir t;
  const test::Result a =
      gen(t, {"--model", "physics", "--window", "285..292/300..306", "--what", "features", "--format", "csv,h5"},
          t.w() / "a");
  ASSERT_EQ(a.status, 0) << test::describe(a);
  const auto rows = test::csv_cells(t.w() / "a" / "scenarios.csv");
  ASSERT_EQ(rows.size(), 41u);
  Plan plan = test::physics_plan(9);
  set_knob(plan, *find_knob("window"), "285..292/300..306", "--window");
  for (const char* key : {"window_lo", "window_hi"}) {
    const auto col = std::find(rows[0].begin(), rows[0].end(), key);
    ASSERT_NE(col, rows[0].end()) << key;
    const size_t c = static_cast<size_t>(col - rows[0].begin());
    for (size_t i = 1; i < rows.size(); ++i) {
      const double want =
          std::string(key) == "window_lo" ? window_lo_at(plan.model, i - 1) : window_hi_at(plan.model, i - 1);
      EXPECT_EQ(std::stod(rows[i][c]), want) << key << " " << i;
    }
  }
  std::set<std::string> params;
  for (const H5Dataset& d : read_h5_layout((t.w() / "a" / "data.h5").string()).datasets)
    if (d.type == TensorType::f64) params.insert(d.name);
  EXPECT_TRUE(params.count("param_window_lo") && params.count("param_window_hi"));
  EXPECT_NE(test::slurp(t.w() / "a" / "manifest.json").find("\"window\": \"285..292/300..306\""), std::string::npos);
}

TEST(DrawnKnobs, BadRangesAreRefusedNamingTheFlagOrTheLine) {
  test::TempDir t;
  const std::vector<std::pair<std::string, std::string>> flags = {
      {"6..0", "--metal-noise: \"6..0\" is reversed"},
      {"0..200", "--metal-noise (B of A..B): 200 is out of range"},
      {"nan..3", "--metal-noise (A of A..B): \"nan\" is not a whole number"},
      {"1.5..3", "is not a whole number"},
      {"..3", "(A of A..B)"},
  };
  for (const auto& [value, says] : flags) {
    const test::Result r = gen(t, {"--metal-noise", value}, t.w() / "o");
    EXPECT_EQ(r.status, 2) << value;
    EXPECT_NE(r.err.find(says), std::string::npos) << value << ": " << r.err;
    EXPECT_FALSE(fs::exists(t.w() / "o")) << value;
  }
  const std::vector<std::pair<std::string, std::string>> windows = {
      {"292..285/300..306", "--window (L1..L2 of L1..L2/H1..H2): \"292..285\" is reversed"},
      {"285..301/300..306", "--window: \"285..301/300..306\": the low end's range must lie below the high end's"},
      {"285..292/300..1200", "--window (H1..H2 of L1..L2/H1..H2): \"300..1200\" must be finite and within 0 .. 1000"},
      {"nan/300", "--window (L1..L2 of L1..L2/H1..H2): \"nan\" must be finite"},
      {"285..292/", "--window (H1..H2 of L1..L2/H1..H2): \"\" is not a number or a range A..B"},
      {"auto/300", "--window (L1..L2 of L1..L2/H1..H2): \"auto\" is not a number"},
  };
  for (const auto& [value, says] : windows) {
    const test::Result r = gen(t, {"--model", "physics", "--window", value}, t.w() / "o");
    EXPECT_EQ(r.status, 2) << value;
    EXPECT_NE(r.err.find(says), std::string::npos) << value << ": " << r.err;
    EXPECT_FALSE(fs::exists(t.w() / "o")) << value;
  }
  const test::Result r = test::generate_spec(t, "count = 10\nmetal_noise = \"9..2\"\n", t.w() / "s");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("spec.toml:2: metal_noise: \"9..2\" is reversed"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(t.w() / "s"));
  const test::Result w =
      test::generate_spec(t, "count = 10\nmodel = \"physics\"\nwindow = \"285..301/300..306\"\n", t.w() / "s");
  EXPECT_NE(w.status, 0);
  EXPECT_NE(w.err.find("spec.toml:3: window: \"285..301/300..306\": the low end's range"), std::string::npos) << w.err;
  EXPECT_FALSE(fs::exists(t.w() / "s"));
}

}  // namespace
}  // namespace portalsim
