// Folds and seams of the outer garment (--clothing-folds, AssetSet::folds): the pattern lies
// on the body only, the kernels' images and features are the fp64 reference's under it, the
// folds cool the IR surface exactly where the pattern is, each row's share is recorded, and
// bad values are refused.
#include <gtest/gtest.h>

#include "backend/compare.h"
#include "parity_support.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "sink/h5_file.h"
#include "support.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

Plan folded_plan(const std::string& clothing, const std::string& folds, Tier tier, bool fused) {
  Plan plan = clothed_plan(61, clothing, tier, fused);
  set_knob(plan, *find_knob("clothing_folds"), folds, "--clothing-folds");
  return plan;
}

// The pattern lies on the body: zero wherever a view's base is the room behind (MMW: nearer
// the background's gray than the subject's; IR: cooler than halfway from the room to the
// skin), and somewhere doubled on every subject's every view.
TEST(ClothingFolds, ThePatternLiesOnTheBodyOnly) {
  const Catalogue& cat = catalogue();
  const PhysicsConfig& pc = cat.physics;
  ASSERT_EQ(assets().folds.size(), cat.subjects.size());
  for (size_t s = 0; s < cat.subjects.size(); ++s) {
    ASSERT_EQ(assets().folds[s].size(), cat.sensors.size());
    for (size_t v = 0; v < cat.sensors.size(); ++v) {
      SCOPED_TRACE(cat.subjects[s].name + " " + cat.sensors[v].name);
      const Image &base = assets().bases[s][v], &folds = assets().folds[s][v];
      ASSERT_EQ(folds.width, base.width);
      ASSERT_EQ(folds.height, base.height);
      const bool ir = cat.sensors[v].camera == Camera::ir;
      size_t on = 0, full = 0;
      for (int y = 0; y < base.height; ++y)
        for (int x = 0; x < base.width; ++x) {
          const double b = base.at(x, y);
          const bool room = ir ? pc.ir_index_min_k + (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0 * b <
                                     (pc.room_temperature + pc.skin_temperature) / 2
                               : std::abs(b - pc.base_background_gray) < std::abs(b - cat.subjects[s].mmw_level);
          if (room) {
            EXPECT_EQ(folds.at(x, y), 0) << x << "," << y;
          }
          on += folds.at(x, y) > 0;
          full += folds.at(x, y) == 255;
        }
      EXPECT_GT(on, base.pixels.size() / 50);
      EXPECT_GT(full, 0u);  // the seams
    }
  }
}

// The kernels' MMW and IR images under drawn folds are the reference's within each camera's
// parity tolerance (1 gray level or index, at most 0.5% off by one), in the standard and
// exact tiers, fused and as the chain of stage kernels, alone and with the illumination and
// worn time drawn too; the features-only path (untabulated, as every drawn outfit) within the
// tolerance table's. The folds reach the images: a run without them gives others.
TEST(ClothingFolds, FoldsAreTheReferencesOnEveryPath) {
  const auto [batch, ref, ocl] = parity_run(0, 900);
  expect_drawn_images_parity(
      *ref, *ocl, batch, [](Tier tier, bool fused) { return folded_plan("random", "0..1", tier, fused); },
      [](Plan& p) { set_knob(p, *find_knob("clothing_folds"), "0", "--clothing-folds"); });
  // Features only, in a window no outfit's body leaves.
  Plan features;
  BatchOutput k, smooth;
  ASSERT_NO_FATAL_FAILURE(expect_raw_features_parity(*ref, *ocl, batch, folded_plan("random", "0..1", Tier::fast, true),
                                                     "untabulated", features, k));
  set_knob(features, *find_knob("clothing_folds"), "0", "--clothing-folds");
  ocl->run(batch, features, smooth);
  EXPECT_NE(k.features, smooth.features);
}

// The extremes, each on every subject: the heaviest coat and a shirt wholly folded (share 1),
// and bare skin, which has no garment to fold (its images are those without folds, byte for
// byte); share 0 is no folds, byte for byte.
TEST(ClothingFolds, TheExtremesAreTheReferences) {
  const auto [batch, ref, ocl] = parity_run(4000, 0);
  for (const char* clothing : {"coat", "shirt", "none"}) {
    SCOPED_TRACE(clothing);
    const Plan plan = folded_plan(clothing, "1", Tier::standard, true);
    BatchOutput r, k, smooth, zero;
    ref->run(batch, plan, r);
    ocl->run(batch, plan, k);
    const OutputDiff d = compare_outputs(k, r);
    test::expect_camera_parity(d.of(Camera::mmw));
    test::expect_camera_parity(d.of(Camera::ir));
    Plan plain = plan;
    set_knob(plain, *find_knob("clothing_folds"), "0", "--clothing-folds");
    ocl->run(batch, plain, smooth);
    Plan at_zero = plan;
    set_knob(at_zero, *find_knob("clothing_folds"), "0..0", "--clothing-folds");
    ocl->run(batch, at_zero, zero);
    for (size_t v = 0; v < k.views.size(); ++v) {
      EXPECT_EQ(zero.views[v].pixels, smooth.views[v].pixels) << v;
      if (std::string(clothing) == "none") {
        EXPECT_EQ(k.views[v].pixels, smooth.views[v].pixels) << v;
      }
    }
  }
}

// Assets built without fold patterns (a run that gives no --clothing-folds) refuse a plan
// with folds on both backends rather than read past the atlas; with no folds they run.
TEST(ClothingFolds, AssetsWithoutPatternsRefuseFolds) {
  const AssetSet bare = build_assets(catalogue(), false);
  EXPECT_TRUE(bare.folds.empty());
  const SceneBatch batch = test::batch_of({test::random_scenario(catalogue(), 1, 3)}, 0);
  auto ref = make_reference_backend(catalogue(), bare);
  auto ocl = make_opencl_backend(catalogue(), bare, test::runtime());
  BatchOutput out;
  EXPECT_ANY_THROW(ocl->run(batch, folded_plan("coat", "0.5", Tier::standard, true), out));
  EXPECT_ANY_THROW(ref->run(batch, folded_plan("coat", "0.5", Tier::standard, true), out));
  BatchOutput k, r;
  ocl->run(batch, folded_plan("coat", "0", Tier::standard, true), k);
  ref->run(batch, folded_plan("coat", "0", Tier::standard, true), r);
  test::expect_camera_parity(compare_outputs(k, r).of(Camera::mmw));
}

// In IR a fold holds more of the skin's warmth in: the surface is cooler where the pattern
// is, by more with a heavier share, and unchanged where it is not (no noise, no objects).
TEST(ClothingFolds, FoldsCoolTheIrSurfaceWhereThePatternIs) {
  const Catalogue& cat = catalogue();
  std::vector<Scenario> scenes(10);
  for (size_t k = 0; k < scenes.size(); ++k) scenes[k].subject = static_cast<int>(k % cat.subjects.size());
  const SceneBatch batch = test::batch_of(scenes, 0);
  auto ocl = make_opencl_backend(cat, assets(), test::runtime());
  const size_t ir = static_cast<size_t>(cat.sensor_index("ir"));
  BatchOutput none, half, full;
  ocl->run(batch, folded_plan("jacket", "0", Tier::standard, true), none);
  ocl->run(batch, folded_plan("jacket", "0.5", Tier::standard, true), half);
  ocl->run(batch, folded_plan("jacket", "1", Tier::standard, true), full);
  for (size_t i = 0; i < scenes.size(); ++i) {
    const Image& folds = assets().folds[static_cast<size_t>(scenes[i].subject)][ir];
    size_t cooler = 0;
    for (size_t p = 0; p < none.views[ir].pixels_per_image(); ++p) {
      const int a = none.views[ir].of(i)[p], b = half.views[ir].of(i)[p], c = full.views[ir].of(i)[p];
      if (folds.pixels[p] == 0) {
        EXPECT_EQ(a, c) << i << " " << p;
        continue;
      }
      EXPECT_LE(b, a) << i << " " << p;
      EXPECT_LE(c, b) << i << " " << p;
      cooler += c < a;
    }
    EXPECT_GT(cooler, 100u) << i;
  }
}

test::Result gen(const test::TempDir& t, std::vector<std::string> args, const fs::path& out) {
  args.insert(args.end(), {"--count", "40", "--seed", "9"});
  return test::generate(t, args, out);
}

// Each row records its share (as drawn_knob_at draws it), the same for any batch, in
// scenarios.csv and data.h5; a fixed share keeps the columns out; the list re-runs.
TEST(ClothingFolds, EachRowsShareIsRecorded) {
  test::TempDir t;
  const std::vector<std::string> folded = {"--model",          "physics", "--clothing", "random",
                                           "--clothing-folds", "0..1",    "--format",   "csv,h5"};
  std::vector<std::string> a_args = folded, b_args = folded;
  a_args.insert(a_args.end(), {"--batch", "7"});
  b_args.insert(b_args.end(), {"--batch", "40", "--threads", "1"});
  const test::Result a = gen(t, a_args, t.w() / "a");
  ASSERT_EQ(a.status, 0) << test::describe(a);
  ASSERT_EQ(gen(t, b_args, t.w() / "b").status, 0);
  for (const char* f : {"scenarios.csv", "features.csv", "data.h5"})
    EXPECT_EQ(test::slurp(t.w() / "a" / f), test::slurp(t.w() / "b" / f)) << f;
  bool param = false;
  for (const H5Dataset& d : read_h5_layout((t.w() / "a" / "data.h5").string()).datasets)
    param = param || (d.name == "param_clothing_folds" && d.type == TensorType::f64);
  EXPECT_TRUE(param);
  const auto rows = test::csv_cells(t.w() / "a" / "scenarios.csv");
  ASSERT_EQ(rows.size(), 41u);
  const auto col = std::find(rows[0].begin(), rows[0].end(), "clothing_folds");
  ASSERT_NE(col, rows[0].end());
  const size_t c = static_cast<size_t>(col - rows[0].begin());
  Plan plan = test::physics_plan(9);
  set_knob(plan, *find_knob("clothing"), "random", "--clothing");
  set_knob(plan, *find_knob("clothing_folds"), "0..1", "--clothing-folds");
  for (size_t i = 1; i < rows.size(); ++i)
    EXPECT_NEAR(std::stod(rows[i][c]), drawn_knob_at(plan.model, PS_DRAWN_CLOTHING_FOLDS, i - 1), 1e-6) << i;
  EXPECT_NE(test::slurp(t.w() / "a" / "manifest.json").find("\"clothing_folds\": \"0..1\""), std::string::npos);
  std::vector<std::string> c_args = folded;
  c_args.insert(c_args.end(), {"--scenarios", (t.w() / "a" / "scenarios.csv").string()});
  ASSERT_EQ(gen(t, c_args, t.w() / "c").status, 0);
  EXPECT_EQ(test::slurp(t.w() / "a" / "scenarios.csv"), test::slurp(t.w() / "c" / "scenarios.csv"));
  // Without folds: no key in the manifest, no column.
  ASSERT_EQ(gen(t, {"--model", "physics", "--clothing", "random"}, t.w() / "d").status, 0);
  EXPECT_EQ(test::slurp(t.w() / "d" / "manifest.json").find("clothing_folds"), std::string::npos);
  EXPECT_EQ(test::slurp(t.w() / "d" / "scenarios.csv").find("clothing_folds"), std::string::npos);
}

TEST(ClothingFolds, BadValuesAreRefusedNamingTheFlagOrTheLine) {
  test::TempDir t;
  const std::vector<std::string> dressed = {"--model", "physics", "--clothing", "random", "--clothing-folds"};
  const auto with = [&](const std::string& v) {
    std::vector<std::string> a = dressed;
    a.push_back(v);
    return a;
  };
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {with("1.5"), "--clothing-folds"},
      {with("-0.1"), "--clothing-folds"},
      {with("1..0.5"), "--clothing-folds"},
      {with("nan"), "--clothing-folds"},
      {with("0..2"), "--clothing-folds"},
      {{"--model", "physics", "--clothing-folds", "0.5"}, "--clothing-folds: folds belong to an outfit"},
      {{"--clothing-folds", "0..1"}, "--clothing-folds: folds belong to an outfit"},
  };
  for (const auto& [args, says] : cases) test::expect_generate_refused(t, args, says);
  test::expect_spec_refused(t, "count = 10\nmodel = \"physics\"\nclothing = \"coat\"\nclothing_folds = \"0.5..3\"\n",
                            "spec.toml:4: clothing_folds");
}

}  // namespace
}  // namespace portalsim::test
