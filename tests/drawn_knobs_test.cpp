// Knobs drawn per scenario (A..B, plan.h ModelSettings::drawn): each scenario's value from
// the counter generator, the same on both backends and in every batch, recorded per row,
// and a fixed value (A..A) keeping today's bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <sstream>
#include <variant>

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

// The fp64 reference and the kernels, on the built-in catalogue.
struct Backends {
  std::unique_ptr<Backend> ref = make_reference_backend(catalogue(), assets());
  std::unique_ptr<Backend> ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  // The kernels' run of `plan` (into `k`) against the reference's of `ref_plan`.
  OutputDiff compare(const SceneBatch& batch, const Plan& ref_plan, const Plan& plan, BatchOutput& k) const {
    BatchOutput r;
    ref->run(batch, ref_plan, r);
    ocl->run(batch, plan, k);
    return compare_outputs(k, r);
  }
  // Features only (`features` keeps no image): the kernels' features (into `k`) are the
  // reference's (from its images, `with_images`) within the tolerance table's.
  void expect_features_within(const SceneBatch& batch, const Plan& with_images, const Plan& features, Model model,
                              Tier tier, BatchOutput& k) const {
    const OutputDiff d = compare(batch, with_images, features, k);
    ASSERT_TRUE(d.features_only);
    EXPECT_EQ(check_tolerance(d, model_tolerance(model, tier)), "");
  }
};

// `n` random scenarios of up to 6 objects, from scenario `first`.
SceneBatch random_batch(size_t n, uint64_t first) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < n; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  return test::batch_of(scenes, first);
}

// `plan` in `tier`, fused or as the chain of stage kernels.
Plan on_path(Plan plan, Tier tier, bool fused) {
  plan.fidelity = tier_fidelity(tier);
  plan.fidelity.fused = fused;
  return plan;
}

// `check(tier, fused)` in each of `tiers`, fused and as the chain of stage kernels.
template <class Check>
void each_path(std::initializer_list<Tier> tiers, const Check& check) {
  for (Tier tier : tiers)
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      check(tier, fused);
    }
}

// A range of one value is that value, to the byte: every view of `one` is `fixed`'s.
void expect_same_views(const BatchOutput& one, const BatchOutput& fixed) {
  ASSERT_EQ(one.views.size(), fixed.views.size());
  for (size_t v = 0; v < one.views.size(); ++v) EXPECT_EQ(one.views[v].pixels, fixed.views[v].pixels) << v;
}

TEST(DrawnKnobs, MetalNoiseDrawnPerScenarioIsTheReferencesOnBothModels) {
  const Backends b;
  Backend *ref = b.ref.get(), *ocl = b.ocl.get();
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
      for (Backend* be : {ref, ocl})
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
    const double v = drawn_knob_at(m, PS_DRAWN_METAL_NOISE, i);
    EXPECT_EQ(v, std::floor(v));
    EXPECT_GE(v, 3);
    EXPECT_LE(v, 9);
    EXPECT_EQ(m.at_scenario(i).metal_noise, v);
    seen.insert(static_cast<int>(v));
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

// Each scenario's image is as noisy as its draw: against the noise-free image (`quiet`), the
// mean squared difference of view `view` over the scenarios whose `noise(index)` is above
// `high` is over 4 times that over those below `low`.
void expect_noise_follows_draw(const SceneBatch& batch, const BatchOutput& noisy, const BatchOutput& quiet, size_t view,
                               const std::function<double(uint64_t)>& noise, double low, double high) {
  double below = 0, above = 0;
  int nl = 0, nh = 0;
  for (size_t i = 0; i < batch.size(); ++i) {
    const double ms = mean_square_difference(noisy.views[view], quiet.views[view], i);
    const double n = noise(batch.first_index + i);
    if (n < low) below += ms, ++nl;
    if (n > high) above += ms, ++nh;
  }
  ASSERT_GT(nl, 0);
  ASSERT_GT(nh, 0);
  EXPECT_GT(above / nh, 4 * (below / nl));
}

// Features only under the block-mean model, where nothing clips: each feature's noise in `d`
// (against `quiet`) is `scale(index)` times `unit`'s, within 0.01 gray levels (fp32 features
// near 128, rounding about 1e-5 of them, summed over up to a hundred noise terms); at least
// `least` features checked.
void expect_feature_noise_scaled(const SceneBatch& batch, const BatchOutput& d, const BatchOutput& unit,
                                 const BatchOutput& quiet, const std::function<double(uint64_t)>& scale, size_t least) {
  const size_t row = d.layout.image_features();
  ASSERT_EQ(d.features.size(), unit.features.size());
  ASSERT_EQ(d.features.size(), quiet.features.size());
  size_t checked = 0, off = 0;
  double worst = 0;
  for (size_t i = 0; i < batch.size(); ++i) {
    const double s = scale(batch.first_index + i);
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
  EXPECT_GT(checked, least);
  EXPECT_EQ(off, 0u) << "worst " << worst;
}

// The IR NETD drawn per scenario: the kernels' images are the reference's within the IR
// parity test's stated tolerance (IrPhysics.KernelsMatchTheReferenceInEveryTier), on the
// fused path and the chain of stage kernels; a scenario's noise is its own draw's.
TEST(DrawnKnobs, IrNetdDrawnPerScenarioIsTheReferencesOnEveryPath) {
  const SceneBatch batch = random_batch(kScenes, 300);
  const Backends b;
  const auto plan_of = [](const std::string& ir_netd, bool fused, Tier tier) {
    Plan plan = on_path(test::physics_plan(31), tier, fused);
    set_knob(plan, *find_knob("ir_netd"), ir_netd, "--ir-netd");
    return plan;
  };
  const size_t ir = static_cast<size_t>(catalogue().sensor_index("ir"));
  each_path({Tier::standard, Tier::exact}, [&](Tier tier, bool fused) {
    const Plan drawn = plan_of("0..0.6", fused, tier);
    BatchOutput k;
    const OutputDiff d = b.compare(batch, drawn, drawn, k);
    EXPECT_GT(d.of(Camera::ir).pixels, 0u);
    test::expect_camera_parity(d.of(Camera::ir));
    // A range of one value is that value, to the byte.
    BatchOutput one, fixed;
    b.ocl->run(batch, plan_of("0.2..0.2", fused, tier), one);
    b.ocl->run(batch, plan_of("0.2", fused, tier), fixed);
    EXPECT_EQ(one.views[ir].pixels, fixed.views[ir].pixels);
    // Each scenario's image is noisier where its draw is larger: against the noise-free
    // image, the mean squared difference follows the drawn NETD.
    BatchOutput quiet;
    b.ocl->run(batch, plan_of("0", fused, tier), quiet);
    expect_noise_follows_draw(
        batch, k, quiet, ir, [&](uint64_t i) { return drawn_knob_at(drawn.model, PS_DRAWN_IR_NETD, i); }, 0.15, 0.45);
  });
}

// Scenario `index`'s MMW noise, its drawn NETD over the root of its drawn frames.
double mmw_noise_at(const ModelSettings& m, uint64_t index) {
  return drawn_knob_at(m, PS_DRAWN_NETD, index) / std::sqrt(drawn_knob_at(m, PS_DRAWN_FRAMES, index));
}

// The MMW camera's NETD and frames drawn per scenario (drawn_knob_at): the kernels'
// MMW images are the reference's within the MMW camera's parity tolerance
// (Physics.KernelsMatchTheReferenceInEveryTier: 1 gray level, at most 0.5% off by one) in
// every tier (the fast tier's frames as one draw, Irwin-Hall), fused and as the chain of
// stage kernels; each scenario's noise is its own draw's.
TEST(DrawnKnobs, MmwNetdAndFramesDrawnPerScenarioAreTheReferencesOnEveryPath) {
  // All 40 under the sanitizers too: both noise groups need members.
  const SceneBatch batch = random_batch(40, 700);
  const Backends b;
  const auto plan_of = [](const std::string& netd, const std::string& frames, bool fused, Tier tier) {
    Plan plan = on_path(test::physics_plan(41), tier, fused);
    set_knob(plan, *find_knob("netd"), netd, "--netd");
    set_knob(plan, *find_knob("frames"), frames, "--frames");
    return plan;
  };
  each_path({Tier::standard, Tier::exact, Tier::fast}, [&](Tier tier, bool fused) {
    const Plan drawn = plan_of("0.2..2", "1..9", fused, tier);
    BatchOutput k;
    const OutputDiff d = b.compare(batch, drawn, drawn, k);
    EXPECT_GT(d.of(Camera::mmw).pixels, 0u);
    test::expect_camera_parity(d.of(Camera::mmw));
    // A range of one value is that value, to the byte.
    BatchOutput one, fixed;
    b.ocl->run(batch, plan_of("1.5..1.5", "4..4", fused, tier), one);
    b.ocl->run(batch, plan_of("1.5", "4", fused, tier), fixed);
    expect_same_views(one, fixed);
    // Each scenario's image is as noisy as its draw: against the noise-free image, the
    // mean squared difference follows NETD^2 / frames.
    BatchOutput quiet;
    b.ocl->run(batch, plan_of("0", "1", fused, tier), quiet);
    expect_noise_follows_draw(
        batch, k, quiet, static_cast<size_t>(catalogue().sensor_index("upper")),
        [&](uint64_t i) { return mmw_noise_at(drawn.model, i); }, 0.3, 0.9);
  });
  // Every frame count of the range is drawn, none outside it; the NETD stays in its range.
  const ModelSettings m = plan_of("0.2..2", "1..9", true, Tier::standard).model;
  std::set<double> seen;
  for (uint64_t i = 0; i < 2000; ++i) {
    const ModelSettings at = m.at_scenario(i);
    seen.insert(drawn_knob_at(m, PS_DRAWN_FRAMES, i));
    EXPECT_GE(drawn_knob_at(m, PS_DRAWN_NETD, i), 0.2);
    EXPECT_LT(drawn_knob_at(m, PS_DRAWN_NETD, i), 2.0);
    EXPECT_EQ(at.netd, drawn_knob_at(m, PS_DRAWN_NETD, i));
    EXPECT_EQ(at.frames, drawn_knob_at(m, PS_DRAWN_FRAMES, i));
  }
  EXPECT_EQ(seen, (std::set<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

// The features-only path of the physics model (physics_raw_features) draws the NETD per
// feature, scaled by the scenario's NETD / sqrt(frames) under the block-mean model: with
// the same draws, a scenario's noise is its draw times the noise of NETD 1 over one frame.
// Tolerance (expect_feature_noise_scaled): 0.01 gray levels; the smallest drawn noise is 100
// times that.
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
  expect_feature_noise_scaled(
      batch, d, unit, quiet, [&](uint64_t i) { return mmw_noise_at(drawn.model, i); }, 10000);
}

// Scenarios 0 .. 1999's draws of element `e` lie in [lo, hi), and are at_scenario's.
void expect_draws_within(const ModelSettings& m, unsigned e, double lo, double hi) {
  SCOPED_TRACE("drawn element " + std::to_string(e));
  const auto field = std::get<double ModelSettings::*>(drawn_knobs()[e].field);
  for (uint64_t i = 0; i < 2000; ++i) {
    const double v = drawn_knob_at(m, e, i);
    EXPECT_GE(v, lo);
    EXPECT_LT(v, hi);
    EXPECT_EQ(m.at_scenario(i).*field, v);
  }
}

// The illumination and the worn time drawn per scenario (drawn_knob_at): the kernels' MMW and IR images are the
// reference's within each camera's parity tolerance (1 gray level or index, at most 0.5% off by one), fused and as the
// chain of stage kernels, and the features-only path's features within the tolerance table's (it leaves its tables for
// the raw grid then); each scenario shows its own draw.
TEST(DrawnKnobs, IlluminationAndWornTimeDrawnPerScenarioAreTheReferencesOnEveryPath) {
  const SceneBatch batch = random_batch(kScenes, 1100);
  const Backends b;
  const auto plan_of = [](const std::string& ill, const std::string& worn, bool fused, Tier tier) {
    Plan plan = on_path(test::physics_plan(47), tier, fused);
    plan.model.netd = 0;
    plan.model.ir_netd = 0;
    set_knob(plan, *find_knob("illumination"), ill, "--illumination");
    set_knob(plan, *find_knob("worn_minutes"), worn, "--worn-minutes");
    return plan;
  };
  const size_t upper = static_cast<size_t>(catalogue().sensor_index("upper"));
  each_path({Tier::standard, Tier::exact}, [&](Tier tier, bool fused) {
    const Plan drawn = plan_of("280..310", "0..60", fused, tier);
    BatchOutput k;
    const OutputDiff d = b.compare(batch, drawn, drawn, k);
    EXPECT_GT(d.of(Camera::mmw).pixels, 0u);
    EXPECT_GT(d.of(Camera::ir).pixels, 0u);
    test::expect_camera_parity(d.of(Camera::mmw));
    test::expect_camera_parity(d.of(Camera::ir));
    // A range of one value is that value, to the byte.
    BatchOutput one, fixed;
    b.ocl->run(batch, plan_of("300..300", "20..20", fused, tier), one);
    b.ocl->run(batch, plan_of("300", "20", fused, tier), fixed);
    expect_same_views(one, fixed);
    // The body reflects the illumination: a scenario's MMW view is brighter the warmer its draw.
    double warm = 0, cold = 0;
    int nw = 0, nc = 0;
    for (size_t i = 0; i < batch.size(); ++i) {
      const ViewImages& a = k.views[upper];
      double mean = 0;
      for (size_t p = 0; p < a.pixels_per_image(); ++p) mean += a.of(i)[p];
      mean /= double(a.pixels_per_image());
      const double ill = drawn_knob_at(drawn.model, PS_DRAWN_ILLUMINATION, batch.first_index + i);
      if (ill > 302) warm += mean, ++nw;
      if (ill < 288) cold += mean, ++nc;
    }
    ASSERT_GT(nw, 0);
    ASSERT_GT(nc, 0);
    EXPECT_GT(warm / nw, cold / nc + 10);
  });
  // Features only: the raw-grid path, its untabulated variant, which leaves the pixels'
  // clipping out: a window no draw's body reaches.
  Plan with_images = plan_of("280..310", "0..60", true, Tier::fast);
  with_images.model.window_lo = 250;
  with_images.model.window_hi = 340;
  Plan features = with_images;
  features.images = 0;
  ASSERT_EQ(test::features_path(*b.ocl, features), "physics_raw_features");
  const std::vector<std::string> paths = b.ocl->paths(features);
  EXPECT_NE(std::find(paths.begin(), paths.end(), "features: physics_raw_features (untabulated)"), paths.end());
  BatchOutput k;
  b.expect_features_within(batch, with_images, features, Model::physics, Tier::fast, k);
  // Each knob's draws stay in its range.
  expect_draws_within(features.model, PS_DRAWN_ILLUMINATION, 280, 310);
  expect_draws_within(features.model, PS_DRAWN_WORN_MINUTES, 0, 60);
}

// The thesis model's pixel noise drawn per scenario (drawn_knob_at): the kernels' images
// are the reference's within the thesis tolerance table's, in every tier, on the fused
// render and the chain of stage kernels, and so are the features-only path's features under
// the per-pixel noise model; the block-mean features scale their noise by the scenario's
// sigma (the same draws: a scenario's noise is its sigma times sigma 1's).
TEST(DrawnKnobs, PixelNoiseDrawnPerScenarioIsTheReferencesOnEveryPath) {
  const SceneBatch batch = random_batch(kScenes, 1300);
  const Backends b;
  const auto plan_of = [](const std::string& sigma, bool fused, Tier tier) {
    Plan plan = on_path(Plan{}, tier, fused);
    plan.model.seed = 53;
    set_knob(plan, *find_knob("pixel_noise"), sigma, "--pixel-noise");
    return plan;
  };
  const auto sigma_of = [](const Plan& plan) {
    return [&plan](uint64_t i) { return drawn_knob_at(plan.model, PS_DRAWN_PIXEL_NOISE, i); };
  };
  each_path({Tier::standard, Tier::exact, Tier::fast}, [&](Tier tier, bool fused) {
    const Plan drawn = plan_of("0..6", fused, tier);
    BatchOutput k;
    EXPECT_EQ(check_tolerance(b.compare(batch, drawn, drawn, k), model_tolerance(Model::thesis, tier)), "");
    // A range of one value is that value, to the byte.
    BatchOutput one, fixed;
    b.ocl->run(batch, plan_of("2.5..2.5", fused, tier), one);
    b.ocl->run(batch, plan_of("2.5", fused, tier), fixed);
    expect_same_views(one, fixed);
    // Each scenario's image is as noisy as its draw.
    BatchOutput quiet;
    b.ocl->run(batch, plan_of("0", fused, tier), quiet);
    expect_noise_follows_draw(batch, k, quiet, static_cast<size_t>(catalogue().sensor_index("upper")), sigma_of(drawn),
                              1.5, 4.5);
  });
  // Features only under the per-pixel noise model (fp32 and fp64): the kernels' features are
  // the reference's (from its images) within the features-only bounds.
  for (Tier tier : {Tier::standard, Tier::exact}) {
    SCOPED_TRACE(std::string(tier_name(tier)) + " features only, per-pixel noise");
    const Plan with_images = plan_of("0..6", true, tier);
    Plan features = with_images;
    features.images = 0;
    ASSERT_TRUE(features.pixel_noise_per_pixel());
    BatchOutput k;
    b.expect_features_within(batch, with_images, features, Model::thesis, tier, k);
  }
  // Features only under the block-mean model: each feature's noise is sigma times sigma 1's
  // (one multiply; the smallest drawn noise's sd is over 100 times the tolerance).
  const auto features_of = [&](const std::string& sigma) {
    Plan plan = plan_of(sigma, true, Tier::fast);
    plan.images = 0;
    plan.metal = false;
    return plan;
  };
  const Plan d_plan = features_of("0.5..6");
  ASSERT_FALSE(d_plan.pixel_noise_per_pixel());
  BatchOutput d, unit, quiet;
  b.ocl->run(batch, d_plan, d);
  b.ocl->run(batch, features_of("1"), unit);
  b.ocl->run(batch, features_of("0"), quiet);
  expect_feature_noise_scaled(batch, d, unit, quiet, sigma_of(d_plan), 1000);
}

// Every drawn knob at the ends of its bounds: a range of one value there is that value to
// the byte, and the whole bounds drawn hold the kernels to the reference within the
// tolerance table's (standard tier) on the model the knob acts in.
TEST(DrawnKnobs, EachKnobAtTheEndsOfItsBoundsIsTheReferences) {
  const SceneBatch batch = random_batch(12, 1500);
  const Backends b;
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
      b.ocl->run(batch, plan_of(end + ".." + end), one);
      b.ocl->run(batch, plan_of(end), fixed);
      expect_same_views(one, fixed);
      EXPECT_EQ(one.metal, fixed.metal);
    }
    SCOPED_TRACE(knob.key + " = " + lo + ".." + hi);
    const Plan whole = plan_of(lo + ".." + hi);
    BatchOutput k;
    EXPECT_EQ(check_tolerance(b.compare(batch, whole, whole, k), model_tolerance(model, Tier::standard)), "");
  }
  // Every number the knob draw stream's elements draw belongs to a knob: one of these, or an
  // end of a range knob whose ends are drawn (the window, its own test below).
  size_t ends = 0, numbers = 0;
  for (const Knob& knob : knobs()) ends += knob.drawn_ends[0] >= 0 ? 2 : 0;
  for (const DrawnKnob& d : drawn_knobs()) numbers += d.number();
  EXPECT_EQ(drawable + ends, numbers);
}

// The MMW display window's ends drawn per scenario (--window L1..L2/H1..H2: drawn_knob_at,
// PS_DRAWN_WINDOW_LO and _HI; kernels/window.cl puts the scenario's ends on the range's low ends before
// the display, the reference shows each scenario through its own window): the kernels' MMW
// images are the reference's within the MMW camera's parity tolerance (1 gray level, at most
// 0.5% off by one) in every tier, fused and as the chain of stage kernels, and at the knob's
// bounds; each scenario's image is the one its window gives when fixed; IR and metal move
// not; the features-only run leaves the tables for the pooled images.
TEST(DrawnKnobs, WindowEndsDrawnPerScenarioAreTheReferencesOnEveryPath) {
  const SceneBatch batch = random_batch(kScenes, 1700);
  const Backends b;
  const auto plan_of = [](const std::string& window, bool fused, Tier tier) {
    Plan plan = on_path(test::physics_plan(61), tier, fused);
    set_knob(plan, *find_knob("window"), window, "--window");
    return plan;
  };
  const size_t upper = static_cast<size_t>(catalogue().sensor_index("upper"));
  const auto mmw_within = [](const OutputDiff& d) {
    EXPECT_GT(d.of(Camera::mmw).pixels, 0u);
    test::expect_camera_parity(d.of(Camera::mmw));
    EXPECT_EQ(d.metal_exact, 1.0);
  };
  each_path({Tier::standard, Tier::exact, Tier::fast}, [&](Tier tier, bool fused) {
    const Plan drawn = plan_of("285..292/300..306", fused, tier);
    BatchOutput k;
    mmw_within(b.compare(batch, drawn, drawn, k));
    // The IR views and the metal are the fixed window's run's, to the byte.
    BatchOutput fixed;
    b.ocl->run(batch, plan_of("285..300", fused, tier), fixed);
    EXPECT_EQ(k.metal, fixed.metal);
    for (size_t v = 0; v < k.views.size(); ++v) {
      if (catalogue().sensors[v].camera == Camera::ir) {
        EXPECT_EQ(k.views[v].pixels, fixed.views[v].pixels) << v;
      }
    }
    EXPECT_NE(k.views[upper].pixels, fixed.views[upper].pixels);
  });
  {
    // Ranges of one value are that window, to the byte.
    BatchOutput one, fixed;
    b.ocl->run(batch, plan_of("290..290/302..302", true, Tier::standard), one);
    b.ocl->run(batch, plan_of("290..302", true, Tier::standard), fixed);
    expect_same_views(one, fixed);
    EXPECT_EQ(find_knob("window")->get(plan_of("290..290/302..302", true, Tier::standard)), "290..302");
    EXPECT_EQ(find_knob("window")->get(plan_of("285..292/302", true, Tier::standard)), "285..292/302");
  }
  {
    // Each scenario's image is its window's, fixed, on a batch of that scenario alone.
    const Plan drawn = plan_of("280..295/297..320", true, Tier::standard);
    BatchOutput k;
    b.ocl->run(batch, drawn, k);
    for (size_t i : {size_t{0}, size_t{3}, batch.size() - 1}) {
      const uint64_t index = batch.first_index + i;
      const std::string own = std::to_string(drawn_knob_at(drawn.model, PS_DRAWN_WINDOW_LO, index)) + ".." +
                              std::to_string(drawn_knob_at(drawn.model, PS_DRAWN_WINDOW_HI, index));
      SCOPED_TRACE("scenario " + std::to_string(index) + ", window " + own);
      BatchOutput alone;
      b.ocl->run(test::batch_of({test::random_scenario(catalogue(), i, 6)}, index), plan_of(own, true, Tier::standard),
                 alone);
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
      BatchOutput k;
      mmw_within(b.compare(batch, drawn, drawn, k));
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
    ASSERT_EQ(test::features_path(*b.ocl, features), "physics_raw_features");
    const std::vector<std::string> paths = b.ocl->paths(features);
    const std::string variant = jitter > 0 ? "untabulated" : "tabulated";
    SCOPED_TRACE(variant);
    EXPECT_NE(std::find(paths.begin(), paths.end(), "features: physics_raw_features (" + variant + ")"), paths.end());
    BatchOutput k, fixed;
    b.expect_features_within(batch, with_images, features, Model::physics, Tier::fast, k);
    Plan fixed_plan = plan_of("240..345", true, Tier::fast);
    fixed_plan.model.jitter = jitter;
    fixed_plan.model.netd = 0;
    fixed_plan.images = 0;
    b.ocl->run(batch, fixed_plan, fixed);
    EXPECT_NE(k.features, fixed.features);
  }
  Plan features = plan_of("285..292/300..306", true, Tier::fast);
  // Each end's draws stay in its range.
  expect_draws_within(features.model, PS_DRAWN_WINDOW_LO, 285, 292);
  expect_draws_within(features.model, PS_DRAWN_WINDOW_HI, 300, 306);
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
  for (size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i][c], std::to_string(m.at_scenario(i - 1).metal_noise)) << i;
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

// evaluate reads a data set's scenarios.csv for its regions' labels: a drawn knob's column there
// is the record it is (plan/knobs.h, drawn_number_keys), not an unknown column.
TEST(DrawnKnobs, EvaluateReadsTheScenarioListOfARunWithDrawnKnobs) {
  test::TempDir t;
  const fs::path data = t.w() / "set", report = t.w() / "report";
  const test::Result g =
      test::generate(t, {"--count",   "200",           "--seed", "3",       "--pool",    "gun,metal-plate",
                         "--objects", "0..2",          "--rule", "gun",     "--balance", "--what",
                         "features",  "--format",      "csv",    "--block", "40",        "--metal-noise",
                         "0..8",      "--pixel-noise", "0..4"},
                     data);
  ASSERT_EQ(g.status, 0) << test::describe(g);
  const std::string head = test::slurp(data / "scenarios.csv").substr(0, 4096);
  EXPECT_NE(head.find("metal_noise"), std::string::npos) << head;
  const test::Result e = test::finish(
      test::start(t.cap(), {"evaluate", data.string(), "--bootstrap", "20", "--no-plot", "--out", report.string()}));
  ASSERT_EQ(e.status, 0) << test::describe(e);
  EXPECT_TRUE(fs::exists(report / "report.json"));
}

// The window's drawn ends: a column each in scenarios.csv (the run's draws, drawn_knob_at),
// float64 datasets in data.h5, the manifest's window as given.
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
  for (const unsigned e : {PS_DRAWN_WINDOW_LO, PS_DRAWN_WINDOW_HI}) {
    const std::string& key = drawn_knobs()[e].key;
    const auto col = std::find(rows[0].begin(), rows[0].end(), key);
    ASSERT_NE(col, rows[0].end()) << key;
    const size_t c = static_cast<size_t>(col - rows[0].begin());
    for (size_t i = 1; i < rows.size(); ++i)
      EXPECT_EQ(std::stod(rows[i][c]), drawn_knob_at(plan.model, e, i - 1)) << key << " " << i;
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
  const auto expect_refused = [&](const std::vector<std::string>& args, const std::string& says) {
    const test::Result r = gen(t, args, t.w() / "o");
    EXPECT_EQ(r.status, 2) << args.back();
    EXPECT_NE(r.err.find(says), std::string::npos) << args.back() << ": " << r.err;
    EXPECT_FALSE(fs::exists(t.w() / "o")) << args.back();
  };
  for (const auto& [value, says] : flags) expect_refused({"--metal-noise", value}, says);
  const std::vector<std::pair<std::string, std::string>> windows = {
      {"292..285/300..306", "--window (L1..L2 of L1..L2/H1..H2): \"292..285\" is reversed"},
      {"285..301/300..306", "--window: \"285..301/300..306\": the low end's range must lie below the high end's"},
      {"285..292/300..1200", "--window (H1..H2 of L1..L2/H1..H2): \"300..1200\" must be finite and within 0 .. 1000"},
      {"nan/300", "--window (L1..L2 of L1..L2/H1..H2): \"nan\" must be finite"},
      {"285..292/", "--window (H1..H2 of L1..L2/H1..H2): \"\" is not a number or a range A..B"},
      {"auto/300", "--window (L1..L2 of L1..L2/H1..H2): \"auto\" is not a number"},
  };
  for (const auto& [value, says] : windows) expect_refused({"--model", "physics", "--window", value}, says);
  for (const auto& [spec, says] : std::vector<std::pair<std::string, std::string>>{
           {"count = 10\nmetal_noise = \"9..2\"\n", "spec.toml:2: metal_noise: \"9..2\" is reversed"},
           {"count = 10\nmodel = \"physics\"\nwindow = \"285..301/300..306\"\n",
            "spec.toml:3: window: \"285..301/300..306\": the low end's range"}}) {
    const test::Result r = test::generate_spec(t, spec, t.w() / "s");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(t.w() / "s"));
  }
}

}  // namespace
}  // namespace portalsim
