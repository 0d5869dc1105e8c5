// The MMW raw grid drawn per scenario from a list (--mmw-raw 14x14,28x28,40x40; plan.h
// raw_grid_at): the OpenCL backend runs each grid's scenarios as a part of their own, their
// indices in a table (kernels/lib/philox.cl, scenario_index); every scenario is what a run at its
// grid alone makes of it, both backends agree, and each row's grid is recorded.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "backend/compare.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "sink/h5_file.h"
#include "support.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

const char* const kGrids = "14x14,28x28,40x40";

Plan grid_plan(const std::string& grids, Tier tier, bool fused) {
  Plan plan = test::physics_plan(23);
  plan.fidelity = tier_fidelity(tier);
  plan.fidelity.fused = fused;
  set_knob(plan, *find_knob("mmw_raw"), grids, "--mmw-raw");
  return plan;
}

// The first index from `from` at which kImageScenes scenarios in a row draw every grid of
// `grids` (so that each grid's part has rows, however few scenarios the build runs).
uint64_t covering_first(const std::string& grids, uint64_t from) {
  const Plan plan = grid_plan(grids, Tier::standard, true);
  for (uint64_t first = from;; ++first) {
    std::set<std::array<int, 2>> drawn;
    for (uint64_t i = first; i < first + kImageScenes; ++i) drawn.insert(raw_grid_at(plan.model, i));
    if (drawn.size() == plan.model.raw_grids.size()) return first;
  }
}

std::vector<Scenario> scenes() {
  std::vector<Scenario> s;
  for (size_t k = 0; k < kImageScenes; ++k) s.push_back(test::random_scenario(catalogue(), k, 6));
  return s;
}

// Every row of `drawn` (a run whose grid is drawn from `grids`) is, to the byte, the row of
// the same scenario in the run of its own grid alone, over the same batch.
void expect_rows_are_their_grids(Backend& b, const SceneBatch& batch, const Plan& drawn, const BatchOutput& out) {
  for (const auto& [w, h] : drawn.model.raw_grids) {
    const std::string grid = std::to_string(w) + "x" + std::to_string(h);
    Plan fixed = drawn;
    set_knob(fixed, *find_knob("mmw_raw"), grid, "--mmw-raw");
    BatchOutput one;
    b.run(batch, fixed, one);
    size_t rows = 0;
    for (size_t i = 0; i < batch.size(); ++i) {
      if (raw_grid_at(drawn.model, batch.index_of(i)) != std::array<int, 2>{w, h}) continue;
      ++rows;
      for (size_t v = 0; v < out.views.size(); ++v) {
        if (out.views[v].empty()) continue;
        EXPECT_TRUE(
            std::equal(out.views[v].of(i), out.views[v].of(i) + out.views[v].pixels_per_image(), one.views[v].of(i)))
            << grid << " view " << v << " scenario " << i;
      }
      if (!out.metal.empty()) {
        EXPECT_TRUE(std::equal(out.metal_of(i), out.metal_of(i) + out.layout.zones, one.metal_of(i))) << i;
      }
      if (!out.features.empty()) {
        EXPECT_TRUE(
            std::equal(out.features_of(i), out.features_of(i) + out.layout.image_features(), one.features_of(i)))
            << grid << " features of scenario " << i;
      }
    }
    EXPECT_GT(rows, 0u) << grid << " is drawn by none of the batch";
  }
}

TEST(RawGridDrawn, EachScenarioIsItsGridsRunAndTheReferencesOnEveryPath) {
  const std::vector<Scenario> s = scenes();
  const SceneBatch batch = test::batch_of(s, covering_first(kGrids, 4100));
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (Tier tier : {Tier::standard, Tier::exact, Tier::fast}) {
    // The reference's rows do not depend on the tier or the path (one run per tier).
    BatchOutput r;
    ref->run(batch, grid_plan(kGrids, tier, true), r);
    if (tier == Tier::standard) expect_rows_are_their_grids(*ref, batch, grid_plan(kGrids, tier, true), r);
    for (bool fused : {true, false}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (fused ? " fused" : " stage chain"));
      const Plan drawn = grid_plan(kGrids, tier, fused);
      BatchOutput k;
      ocl->run(batch, drawn, k);
      EXPECT_EQ(check_tolerance(compare_outputs(k, r), model_tolerance(Model::physics, tier)), "");
      expect_rows_are_their_grids(*ocl, batch, drawn, k);
    }
  }
  // The grids' extremes: a single raw cell, and as many as the views' pixels.
  const Plan ends = grid_plan("1x1,200x200", Tier::standard, true);
  const SceneBatch both = test::batch_of(s, covering_first("1x1,200x200", 4100));
  BatchOutput r, k;
  ref->run(both, ends, r);
  ocl->run(both, ends, k);
  EXPECT_EQ(check_tolerance(compare_outputs(k, r), model_tolerance(Model::physics, Tier::standard)), "");
  expect_rows_are_their_grids(*ocl, both, ends, k);
}

// Features only: the raw-grid features path (tabulated, and untabulated where jitter moves
// the objects) for each grid's part, its rows each the run of their grid alone.
TEST(RawGridDrawn, FeaturesOnlyRowsAreTheirGridsRuns) {
  const std::vector<Scenario> s = scenes();
  const SceneBatch batch = test::batch_of(s, covering_first(kGrids, 900));
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (const double jitter : {0.0, 4.0}) {
    Plan drawn = grid_plan(kGrids, Tier::fast, true);
    drawn.model.jitter = jitter;
    drawn.images = 0;
    ASSERT_EQ(test::features_path(*ocl, drawn), "physics_raw_features");
    BatchOutput k;
    ocl->run(batch, drawn, k);
    expect_rows_are_their_grids(*ocl, batch, drawn, k);
    // The grids differ: the drawn run is none of its grids' runs.
    BatchOutput one;
    ocl->run(batch, grid_plan("28x28", Tier::fast, true), one);
    EXPECT_NE(k.features, one.features);
  }
}

// A batch cut anywhere, and the scenarios in batches of one, make the same rows.
TEST(RawGridDrawn, TheRowsDoNotDependOnTheBatch) {
  const std::vector<Scenario> s = scenes();
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const Plan drawn = grid_plan(kGrids, Tier::standard, true);
  BatchOutput whole;
  ocl->run(test::batch_of(s, 300), drawn, whole);
  const size_t cut = s.size() / 3;
  BatchOutput a, b, joined;
  ocl->run(test::batch_of({s.begin(), s.begin() + cut}, 300), drawn, a);
  ocl->run(test::batch_of({s.begin() + cut, s.end()}, 300 + cut), drawn, b);
  append_output(joined, a);
  append_output(joined, b);
  for (size_t v = 0; v < whole.views.size(); ++v) EXPECT_EQ(whole.views[v].pixels, joined.views[v].pixels) << v;
  EXPECT_EQ(whole.features, joined.features);
  EXPECT_EQ(whole.metal, joined.metal);
  for (size_t i : {size_t{0}, size_t{5}, s.size() - 1}) {
    BatchOutput alone;
    ocl->run(test::batch_of({s[i]}, 300 + i), drawn, alone);
    for (size_t v = 0; v < whole.views.size(); ++v)
      EXPECT_TRUE(std::equal(alone.views[v].of(0), alone.views[v].of(0) + alone.views[v].pixels_per_image(),
                             whole.views[v].of(i)))
          << "view " << v << " scenario " << i;
  }
}

// Every grid of the list is drawn, about as often as another, and nothing else.
TEST(RawGridDrawn, EachGridOfTheListIsDrawnAlike) {
  const Plan drawn = grid_plan("10x12,20x20,30x8", Tier::standard, true);
  EXPECT_EQ(drawn.model.raw_width, 10);
  EXPECT_EQ(drawn.model.raw_height, 12);
  EXPECT_EQ(find_knob("mmw_raw")->get(drawn), "10x12,20x20,30x8");
  std::map<std::array<int, 2>, int> seen;
  for (uint64_t i = 0; i < 3000; ++i) ++seen[raw_grid_at(drawn.model, i)];
  ASSERT_EQ(seen.size(), 3u);
  for (const auto& [g, count] : seen) {
    EXPECT_NE(std::find(drawn.model.raw_grids.begin(), drawn.model.raw_grids.end(), g), drawn.model.raw_grids.end());
    // 1,000 expected; a binomial's sd is 26, so 6 sd either side.
    EXPECT_GT(count, 840);
    EXPECT_LT(count, 1160);
  }
  // One grid is the knob as before: nothing drawn, the manifest's text unchanged.
  const Plan one = grid_plan("28x28", Tier::standard, true);
  EXPECT_FALSE(one.model.raw_grid_drawn());
  EXPECT_EQ(find_knob("mmw_raw")->get(one), "28x28");
  // A view with a raw grid of its own keeps it.
  Sensor own = catalogue().sensors[0];
  own.raw = std::array<int, 2>{24, 24};
  const ModelSettings m = drawn.model.for_view(own);
  EXPECT_FALSE(m.raw_grid_drawn());
  EXPECT_EQ(m.at_scenario(5).raw_width, 24);
}

// No path's gate reads the raw grid, so every grid's part of a batch takes the paths the
// run's plan names (--timing) and renders the views it gives (the pipeline sizes its batches
// by them): a gate that comes to read the grid fails here, and the backend must then route
// each part on its own.
TEST(RawGridDrawn, NoGateReadsTheGrid) {
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (Tier tier : {Tier::standard, Tier::exact, Tier::fast})
    for (const bool fused : {true, false})
      for (const uint32_t images : {kAllViews, 0u}) {
        Plan drawn = grid_plan("1x1,28x28,120x90,200x200", tier, fused);
        drawn.images = images;
        for (const auto& [w, h] : drawn.model.raw_grids) {
          Plan one = drawn;
          set_knob(one, *find_knob("mmw_raw"), std::to_string(w) + "x" + std::to_string(h), "--mmw-raw");
          EXPECT_EQ(ocl->paths(one), ocl->paths(drawn)) << w << "x" << h;
          EXPECT_EQ(ocl->rendered_views(one), ocl->rendered_views(drawn)) << w << "x" << h;
        }
      }
}

test::Result gen(const test::TempDir& t, std::vector<std::string> args, const fs::path& out) {
  if (std::find(args.begin(), args.end(), "--scenarios") == args.end()) args.insert(args.end(), {"--count", "40"});
  args.insert(args.end(), {"--seed", "9", "--model", "physics"});
  return test::generate(t, args, out);
}

TEST(RawGridDrawn, EachScenariosGridIsRecordedWhateverTheBatch) {
  test::TempDir t;
  const test::Result a =
      gen(t, {"--mmw-raw", kGrids, "--what", "both", "--format", "csv,h5", "--batch", "7"}, t.w() / "a");
  ASSERT_EQ(a.status, 0) << test::describe(a);
  ASSERT_EQ(gen(t, {"--mmw-raw", kGrids, "--what", "both", "--format", "csv,h5", "--batch", "40", "--threads", "1"},
                t.w() / "b")
                .status,
            0);
  for (const char* f : {"scenarios.csv", "features.csv", "data.h5"})
    EXPECT_EQ(test::slurp(t.w() / "a" / f), test::slurp(t.w() / "b" / f)) << f;
  const auto rows = test::csv_cells(t.w() / "a" / "scenarios.csv");
  ASSERT_EQ(rows.size(), 41u);
  Plan plan = test::physics_plan(9);
  set_knob(plan, *find_knob("mmw_raw"), kGrids, "--mmw-raw");
  for (size_t side = 0; side < 2; ++side) {
    const auto col = std::find(rows[0].begin(), rows[0].end(), kRawGridColumns[side]);
    ASSERT_NE(col, rows[0].end()) << kRawGridColumns[side];
    const size_t c = static_cast<size_t>(col - rows[0].begin());
    for (size_t i = 1; i < rows.size(); ++i)
      EXPECT_EQ(rows[i][c], std::to_string(raw_grid_at(plan.model, i - 1)[side])) << i;
  }
  std::set<std::string> grids;
  for (const H5Dataset& d : read_h5_layout((t.w() / "a" / "data.h5").string()).datasets)
    if (d.type == TensorType::i16) grids.insert(d.name);
  EXPECT_TRUE(grids.count("mmw_raw_width") && grids.count("mmw_raw_height"));
  EXPECT_NE(test::slurp(t.w() / "a" / "manifest.json").find("\"mmw_raw\": \"14x14,28x28,40x40\""), std::string::npos);
  EXPECT_NE(test::slurp(t.w() / "a" / "croissant.json").find("the MMW camera's raw grid, cells across"),
            std::string::npos);
  // The list re-runs: its grid columns are read as the record they are.
  ASSERT_EQ(gen(t, {"--mmw-raw", kGrids, "--scenarios", (t.w() / "a" / "scenarios.csv").string()}, t.w() / "c").status,
            0);
  EXPECT_EQ(test::slurp(t.w() / "a" / "scenarios.csv"), test::slurp(t.w() / "c" / "scenarios.csv"));
  // A fixed grid writes no grid columns.
  ASSERT_EQ(gen(t, {"--mmw-raw", "28x28"}, t.w() / "d").status, 0);
  EXPECT_EQ(test::slurp(t.w() / "d" / "scenarios.csv").find("mmw_raw"), std::string::npos);
}

TEST(RawGridDrawn, BadListsAreRefusedNamingTheFlagOrTheLine) {
  test::TempDir t;
  const std::vector<std::pair<std::string, std::string>> lists = {
      {"28x28,", "--mmw-raw (grid 2 of the list): empty"},
      {",28x28", "--mmw-raw (grid 1 of the list): empty"},
      {"28x28,28x28", "--mmw-raw (grid 2 of the list): 28x28 is listed twice"},
      {"28x28,0x5", "--mmw-raw (grid 2 of the list): 0x5 is out of range"},
      {"28x28,abc", "--mmw-raw (grid 2 of the list): \"abc\" is not WxH"},
      {"28x28,nanx4", "is not WxH"},
      {"14x14..28x28", "is not WxH"},
      {"28x28,300x300", "--mmw-raw: 300x300 is finer than the upper view (200x200)"},
      {"1x1,2x2,3x3,4x4,5x5,6x6,7x7,8x8,9x9,10x10,11x11,12x12,13x13,14x14,15x15,16x16,17x17", "more than 16 grids"},
  };
  for (const auto& [value, says] : lists) {
    const test::Result r = gen(t, {"--mmw-raw", value}, t.w() / "o");
    EXPECT_EQ(r.status, 2) << value;
    EXPECT_NE(r.err.find(says), std::string::npos) << value << ": " << r.err;
    EXPECT_FALSE(fs::exists(t.w() / "o")) << value;
  }
  // The thesis model has no raw grid to draw.
  const test::Result thesis =
      test::generate(t, {"--mmw-raw", kGrids, "--count", "4", "--model", "thesis"}, t.w() / "o");
  EXPECT_EQ(thesis.status, 2);
  EXPECT_NE(thesis.err.find("--mmw-raw: a list of grids applies to the physics model"), std::string::npos)
      << thesis.err;
  EXPECT_FALSE(fs::exists(t.w() / "o"));
  const test::Result r =
      test::generate_spec(t, "count = 10\nmodel = \"physics\"\nmmw_raw = \"24x24,24x24\"\n", t.w() / "s");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("spec.toml:3: mmw_raw (grid 2 of the list): 24x24 is listed twice"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(t.w() / "s"));
}

}  // namespace
}  // namespace portalsim::test
