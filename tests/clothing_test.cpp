// Clothing drawn per scenario (--clothing, scene/clothing.h): each scenario's outfit from the
// counter generator, the kernels' images and features the fp64 reference's under it, thicker
// clothing hiding more, each row's outfit recorded, and bad values refused.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>

#include "backend/compare.h"
#include "parity_support.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "sink/h5_file.h"
#include "support.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

// Each class is drawn alike, each outfit alike within its class, and every outfit of the
// table is reached; a fixed class draws only its own outfits. 20,000 draws: each class's
// share within 4 standard errors (0.011) of 1/5.
TEST(Clothing, OutfitsAreDrawnByClassThenFabric) {
  const OutfitTable& all = outfit_table(Clothing::random);
  ASSERT_EQ(all.class_first.size(), 5u);
  EXPECT_EQ(all.outfits.size(), 1u + 2 + 6 + 6 + 18);
  EXPECT_EQ(all.outfits[0].name(), "none");
  Plan plan = clothed_plan(53, "random", Tier::standard, true);
  std::vector<int> per_class(5, 0);
  std::set<int> seen;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const int o = outfit_at(plan.model, static_cast<uint64_t>(i));
    ASSERT_GE(o, 0);
    ASSERT_LT(o, static_cast<int>(all.outfits.size()));
    seen.insert(o);
    for (size_t c = 0; c < 5; ++c)
      if (o >= all.class_first[c] && o < all.class_first[c] + all.class_count[c]) ++per_class[c];
  }
  EXPECT_EQ(seen.size(), all.outfits.size());
  for (size_t c = 0; c < 5; ++c) EXPECT_NEAR(per_class[c] / double(n), 0.2, 0.011) << c;
  set_knob(plan, *find_knob("clothing"), "coat", "--clothing");
  for (int i = 0; i < 500; ++i) {
    const Outfit& o = outfit_table(Clothing::coat).outfits.at(static_cast<size_t>(outfit_at(plan.model, i)));
    ASSERT_EQ(o.layers.size(), 3u);
    EXPECT_STREQ(kGarments[o.layers[2].garment].name, "coat");
  }
  set_knob(plan, *find_knob("clothing"), "catalogue", "--clothing");
  EXPECT_EQ(outfit_at(plan.model, 3), -1);
}

// The kernels' MMW and IR images under drawn outfits are the reference's within each
// camera's parity tolerance (Physics.KernelsMatchTheReferenceInEveryTier: 1 gray level or
// index, at most 0.5% off by one), in the standard and exact tiers, fused and as the chain of
// stage kernels, alone and with the illumination and worn time drawn too; the features-only
// path (untabulated: it leaves its tables) within the tolerance table's.
TEST(Clothing, OutfitsAreTheReferencesOnEveryPath) {
  const auto [batch, ref, ocl] = parity_run(0, 700);
  // The outfits reach the images: the catalogue's clothing gives others.
  expect_drawn_images_parity(
      *ref, *ocl, batch, [](Tier tier, bool fused) { return clothed_plan(53, "random", tier, fused); },
      [](Plan& p) { set_knob(p, *find_knob("clothing"), "catalogue", "--clothing"); });
  // Features only, in a window no outfit's body leaves.
  Plan features;
  BatchOutput k;
  expect_raw_features_parity(*ref, *ocl, batch, clothed_plan(53, "random", Tier::fast, true), "untabulated", features,
                             k);
}

// The extremes: no clothing (the base image's skin, every shadow at full depth) and the
// heaviest coat (leather over wool over cotton: 3.8 dB, 1.21 clo), each on every subject,
// hold the kernels to the reference as above.
TEST(Clothing, TheLightestAndHeaviestOutfitsAreTheReferences) {
  const auto [batch, ref, ocl] = parity_run(3000, 0);
  for (const char* clothing : {"none", "coat"}) {
    SCOPED_TRACE(clothing);
    const Plan plan = clothed_plan(53, clothing, Tier::standard, true);
    BatchOutput r, k;
    ref->run(batch, plan, r);
    ocl->run(batch, plan, k);
    const OutputDiff d = compare_outputs(k, r);
    test::expect_camera_parity(d.of(Camera::mmw));
    test::expect_camera_parity(d.of(Camera::ir));
  }
}

// An object shows less under thicker clothing: a steel plate's contrast against the same
// scene without it (summed over the view, in gray levels or IR index levels) falls from no
// clothing to a shirt to a coat, in both cameras, for every drawn fabric of each class.
TEST(Clothing, ThickerClothingShowsLess) {
  const Catalogue& cat = catalogue();
  const int plate = test::variant_of(cat, "metal-plate");
  std::vector<Scenario> with, without;
  for (int k = 0; k < 24; ++k) {
    Scenario s;
    s.subject = k % 5;
    without.push_back(s);
    s.objects[1] = static_cast<int16_t>(plate);  // region 2: the centre of the chest, in the upper and IR views
    with.push_back(s);
  }
  auto ocl = make_opencl_backend(cat, assets(), test::runtime());
  const auto contrast = [&](const char* clothing, size_t view) {
    const Plan plan = clothed_plan(53, clothing, Tier::standard, true);
    BatchOutput a, b;
    ocl->run(test::batch_of(with), plan, a);
    ocl->run(test::batch_of(without), plan, b);
    std::vector<double> c;
    for (size_t i = 0; i < with.size(); ++i) {
      double sum = 0;
      for (size_t p = 0; p < a.views[view].pixels_per_image(); ++p)
        sum += std::abs(double(a.views[view].of(i)[p]) - double(b.views[view].of(i)[p]));
      c.push_back(sum);
    }
    return c;
  };
  for (const char* name : {"upper", "ir"}) {
    SCOPED_TRACE(name);
    const size_t view = static_cast<size_t>(cat.sensor_index(name));
    const std::vector<double> none = contrast("none", view), shirt = contrast("shirt", view),
                              coat = contrast("coat", view);
    for (size_t i = 0; i < with.size(); ++i) {
      EXPECT_GT(none[i], 0) << i;
      EXPECT_GT(none[i], shirt[i]) << i;
      EXPECT_GT(shirt[i], coat[i]) << i;
    }
  }
}

test::Result gen(const test::TempDir& t, std::vector<std::string> args, const fs::path& out) {
  args.insert(args.end(), {"--count", "40", "--seed", "9"});
  return test::generate(t, args, out);
}

// Each row records its outfit (as outfit_at draws it), the same for any batch; the list
// re-runs to the same bytes; the catalogue's clothing leaves the manifest as it was.
TEST(Clothing, EachRowsOutfitIsRecorded) {
  test::TempDir t;
  const std::vector<std::string> physics = {"--model", "physics", "--clothing", "random"};
  std::vector<std::string> a_args = physics, b_args = physics;
  a_args.insert(a_args.end(), {"--batch", "7", "--format", "arff,h5"});
  b_args.insert(b_args.end(), {"--batch", "40", "--threads", "1", "--format", "arff,h5"});
  const test::Result a = gen(t, a_args, t.w() / "a");
  ASSERT_EQ(a.status, 0) << test::describe(a);
  ASSERT_EQ(gen(t, b_args, t.w() / "b").status, 0);
  for (const char* f : {"scenarios.csv", "features.arff", "data.h5"})
    EXPECT_EQ(test::slurp(t.w() / "a" / f), test::slurp(t.w() / "b" / f)) << f;
  std::set<std::string> datasets;
  for (const H5Dataset& d : read_h5_layout((t.w() / "a" / "data.h5").string()).datasets) datasets.insert(d.name);
  for (const char* d : {"clothing_outfit", "clothing_transmission", "clothing_clo"})
    EXPECT_TRUE(datasets.count(d)) << d;
  EXPECT_NE(test::slurp(t.w() / "a" / "croissant.json").find("its outfit's power transmission"), std::string::npos);
  const auto rows = test::csv_cells(t.w() / "a" / "scenarios.csv");
  ASSERT_EQ(rows.size(), 41u);
  const auto col = std::find(rows[0].begin(), rows[0].end(), "clothing");
  ASSERT_NE(col, rows[0].end());
  const size_t c = static_cast<size_t>(col - rows[0].begin());
  EXPECT_EQ(rows[0][c + 1], "clothing_transmission");
  EXPECT_EQ(rows[0][c + 2], "clothing_clo");
  Plan plan = test::physics_plan(9);
  set_knob(plan, *find_knob("clothing"), "random", "--clothing");
  for (size_t i = 1; i < rows.size(); ++i) {
    const Outfit& o = outfit_table(Clothing::random).outfits.at(static_cast<size_t>(outfit_at(plan.model, i - 1)));
    EXPECT_EQ(rows[i][c], o.name()) << i;
    EXPECT_DOUBLE_EQ(std::stod(rows[i][c + 1]), o.transmission()) << i;
    EXPECT_DOUBLE_EQ(std::stod(rows[i][c + 2]), o.clo()) << i;
  }
  EXPECT_NE(test::slurp(t.w() / "a" / "manifest.json").find("\"clothing\": \"random\""), std::string::npos);
  // The list re-runs: its outfit columns are read as the record they are.
  std::vector<std::string> c_args = physics;
  c_args.insert(c_args.end(), {"--scenarios", (t.w() / "a" / "scenarios.csv").string(), "--seed", "9"});
  ASSERT_EQ(test::generate(t, c_args, t.w() / "c").status, 0);
  EXPECT_EQ(test::slurp(t.w() / "a" / "scenarios.csv"), test::slurp(t.w() / "c" / "scenarios.csv"));
  // The catalogue's clothing: no clothing key in the manifest, no clothing columns.
  ASSERT_EQ(gen(t, {"--model", "physics"}, t.w() / "d").status, 0);
  EXPECT_EQ(test::slurp(t.w() / "d" / "manifest.json").find("clothing"), std::string::npos);
  EXPECT_EQ(test::slurp(t.w() / "d" / "scenarios.csv").find("clothing"), std::string::npos);
}

TEST(Clothing, BadValuesAreRefusedNamingTheFlagOrTheLine) {
  test::TempDir t;
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--model", "physics", "--clothing", "silk"}, "--clothing: \"silk\" is not one of"},
      {{"--model", "physics", "--clothing", ""}, "--clothing"},
      {{"--clothing", "coat"}, "--clothing: coat applies to the physics model"},
  };
  for (const auto& [args, says] : cases) test::expect_generate_refused(t, args, says);
  test::expect_spec_refused(t, "count = 10\nmodel = \"physics\"\nclothing = \"kilt\"\n", "spec.toml:3: clothing");
}

}  // namespace
}  // namespace portalsim::test
