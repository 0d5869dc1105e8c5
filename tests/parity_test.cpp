// Kernel against reference, stage by stage, over hundreds of random scenarios that
// cover every object variant, region and subject.
//
// Tolerances: the table in plan/tolerance.h (docs/dev/testing.md); the stage tests below
// hold the standard tier's (fp32 kernels against the fp64 reference).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "backend/compare.h"
#include "base/embedded.h"
#include "plan/tolerance.h"
#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;

struct Diff {
  int max_abs = 0;
  size_t off = 0, total = 0;
};
Diff compare(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  Diff d;
  EXPECT_EQ(a.size(), b.size());
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    const int e = std::abs(int(a[i]) - int(b[i]));
    d.max_abs = std::max(d.max_abs, e);
    d.off += e > 0;
  }
  d.total = a.size();
  return d;
}

// The default catalogue's coverage set (support.h).
std::vector<Scenario> coverage_set(size_t n, int max_objects) { return test::coverage(catalogue(), n, max_objects); }

struct Outputs {
  BatchOutput ref, cl;
};

Outputs run_both(const std::vector<Scenario>& scenes, const Plan& plan, uint64_t first = 0) {
  Outputs o;
  const SceneBatch batch = test::batch_of(scenes, first);
  make_reference_backend(catalogue(), assets())->run(batch, plan, o.ref);
  make_opencl_backend(catalogue(), assets(), test::runtime())->run(batch, plan, o.cl);
  return o;
}

Plan images_only(bool pattern, double sigma) {
  Plan p;
  p.features = false;
  p.metal = false;
  p.model.pattern_noise = pattern;
  p.model.pixel_sigma = sigma;
  p.model.seed = 20260101;
  return p;
}

void expect_images_within_one(const Outputs& o, const char* stage) {
  for (auto [name, a, b] : {std::tuple{"upper", &o.ref.view("upper").pixels, &o.cl.view("upper").pixels},
                            std::tuple{"lower", &o.ref.view("lower").pixels, &o.cl.view("lower").pixels},
                            std::tuple{"ir", &o.ref.view("ir").pixels, &o.cl.view("ir").pixels}}) {
    const Diff d = compare(*a, *b);
    EXPECT_LE(d.max_abs, 1) << stage << " " << name;
    // Ties are rare: fewer than 1 pixel in 1000 may round the other way.
    EXPECT_LT(static_cast<double>(d.off) / d.total, 1e-3) << stage << " " << name;
  }
}

TEST(Parity, CompositeStage) {
  const auto scenes = coverage_set(400, 13);
  const Outputs o = run_both(scenes, images_only(false, 0));
  expect_images_within_one(o, "composite");
  // The stage did something: objects changed pixels away from the base.
  size_t changed = 0;
  for (size_t i = 0; i < scenes.size(); ++i) {
    const Image& base = assets().bases[scenes[i].subject][0];
    for (size_t p = 0; p < base.pixels.size(); ++p) changed += o.cl.view("upper").of(i)[p] != base.pixels[p];
  }
  EXPECT_GT(changed, 100000u);
}

TEST(Parity, NoiseStagePatterns) {
  const auto scenes = coverage_set(400, 13);
  const Outputs with = run_both(scenes, images_only(true, 0));
  expect_images_within_one(with, "pattern noise");
  const Outputs without = run_both(scenes, images_only(false, 0));
  EXPECT_NE(with.cl.view("upper").pixels, without.cl.view("upper").pixels)
      << "noise patterns must change the MMW images";
  EXPECT_EQ(with.cl.view("ir").pixels, without.cl.view("ir").pixels) << "the thesis's noise patterns are MMW only";
}

// The built-in patterns fade to 128 (no change) at their border, so a tile's edge rows and
// columns add nothing there; a catalogue's own image need not. Patterns of random bytes
// make every tile row and column count (mutation 10 of tools/mutations.txt skips the last).
TEST(Parity, NoiseStagePatternsWithoutAQuietBorder) {
  AssetSet noisy = assets();
  for (size_t k = 0; k < noisy.noise.size(); ++k)
    for (size_t p = 0; p < noisy.noise[k].pixels.size(); ++p)
      noisy.noise[k].pixels[p] = static_cast<uint8_t>(draw(77, k, 98, p)[0] & 0xff);
  const auto scenes = coverage_set(200, 13);
  const SceneBatch batch = test::batch_of(scenes);
  for (bool fused : {true, false}) {  // the fused render's tiles, and the stage kernel's
    SCOPED_TRACE(fused ? "fused" : "stage chain");
    Plan plan = images_only(true, 0);
    plan.fidelity.fused = fused;
    Outputs o;
    make_reference_backend(catalogue(), noisy)->run(batch, plan, o.ref);
    make_opencl_backend(catalogue(), noisy, test::runtime())->run(batch, plan, o.cl);
    expect_images_within_one(o, "pattern noise, random tiles");
    const Outputs builtin = run_both(scenes, plan);
    EXPECT_NE(o.cl.view("upper").pixels, builtin.cl.view("upper").pixels) << "the replaced patterns must be used";
  }
}

TEST(Parity, NoiseStagePerPixelGaussian) {
  const auto scenes = coverage_set(200, 4);
  const Outputs o = run_both(scenes, images_only(true, 6.0), 1ull << 40);
  expect_images_within_one(o, "pixel noise");
  // The noise has the asked-for spread where nothing clips: base pixels of an empty scene.
  Scenario empty;
  const Outputs e = run_both({empty}, images_only(false, 6.0));
  const Image& base = assets().bases[0][0];
  double sum = 0, sum2 = 0;
  size_t n = 0;
  for (size_t p = 0; p < base.pixels.size(); ++p) {
    if (base.pixels[p] < 40 || base.pixels[p] > 215) continue;
    const double d = double(e.cl.view("upper").of(0)[p]) - base.pixels[p];
    sum += d;
    sum2 += d * d;
    ++n;
  }
  ASSERT_GT(n, 1000u);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.2);
  EXPECT_NEAR(sd, std::sqrt(36.0 + 1.0 / 12.0), 0.3);  // sigma with rounding to integers
}

TEST(Parity, MetalStageExact) {
  Plan p;
  p.images = 0;
  p.features = false;
  for (int noise : {0, 7}) {
    p.model.metal_noise = noise;
    p.model.seed = 99;
    const Outputs o = run_both(coverage_set(600, 13), p);
    EXPECT_EQ(o.ref.metal, o.cl.metal) << "metal noise " << noise;
  }
}

TEST(Parity, PoolStageFeatures) {
  for (int block : {10, 7, 1, 200}) {
    Plan p;
    p.model.block = block;
    p.model.seed = 5;
    const Outputs o = run_both(coverage_set(block == 1 ? 120 : 300, 13), p);
    ASSERT_EQ(o.ref.features.size(), o.cl.features.size());
    double max_err = 0, sum_err = 0;
    for (size_t k = 0; k < o.ref.features.size(); ++k) {
      const double e = std::abs(double(o.ref.features[k]) - o.cl.features[k]);
      max_err = std::max(max_err, e);
      sum_err += e;
    }
    EXPECT_LE(max_err, 1.0) << "block " << block;
    EXPECT_LE(sum_err / o.ref.features.size(), 0.01) << "block " << block;
    EXPECT_EQ(o.ref.metal, o.cl.metal);
  }
}

TEST(Parity, FeaturesAreMeansOfTheImages) {
  // Pool over the kernel's own images, recomputed here: exact integer sums, so equal to
  // float rounding.
  Plan p;
  p.model.block = 7;
  const auto scenes = coverage_set(60, 6);
  BatchOutput out;
  make_opencl_backend(catalogue(), assets(), test::runtime())->run(test::batch_of(scenes), p, out);
  const int W = out.view("upper").width, H = out.view("upper").height;
  for (size_t i = 0; i < scenes.size(); ++i) {
    const float* f = out.features_of(i);
    // The bottom-right partial block of the lower view: 200 = 28 * 7 + 4.
    const int bx = out.layout.grids[0].blocks_x - 1, by = out.layout.grids[0].blocks_y - 1;
    double sum = 0;
    for (int y = by * 7; y < H; ++y)
      for (int x = bx * 7; x < W; ++x) sum += out.view("lower").of(i)[y * W + x];
    EXPECT_FLOAT_EQ(
        f[out.layout.grids[0].blocks_x * out.layout.grids[0].blocks_y + by * out.layout.grids[0].blocks_x + bx],
        sum / 16.0);
    // Region 3 (left chest, upper view).
    const Rect& r = test::mmw_rect(catalogue(), 2);
    sum = 0;
    for (int y = r.y; y < r.y + r.h; ++y)
      for (int x = r.x; x < r.x + r.w; ++x) sum += out.view("upper").of(i)[y * W + x];
    EXPECT_NEAR(f[2 * out.layout.grids[0].blocks_x * out.layout.grids[0].blocks_y + 2], sum / (r.w * r.h), 1e-3);
  }
}

TEST(Determinism, ScenarioDependsOnlyOnSeedAndIndexNotOnBatch) {
  Plan p;
  p.model.pixel_sigma = 3;
  p.model.metal_noise = 5;
  p.model.seed = 77;
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 40; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 5));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  BatchOutput whole;
  cl->run(test::batch_of(scenes, 1000), p, whole);
  // Scenario 1000 + 17 alone, as the first of a batch.
  BatchOutput one;
  cl->run(test::batch_of({scenes[17]}, 1017), p, one);
  const size_t px = size_t(whole.view("upper").width) * whole.view("upper").height;
  EXPECT_TRUE(std::equal(one.view("upper").pixels.begin(), one.view("upper").pixels.end(),
                         whole.view("upper").pixels.begin() + 17 * px));
  EXPECT_TRUE(std::equal(one.metal.begin(), one.metal.end(), whole.metal.begin() + 17 * kBuiltinZones));
  const size_t F = whole.layout.image_features();
  EXPECT_TRUE(std::equal(one.features.begin(), one.features.end(), whole.features.begin() + 17 * F));
  // Another seed changes the noise.
  p.model.seed = 78;
  BatchOutput other;
  cl->run(test::batch_of({scenes[17]}, 1017), p, other);
  EXPECT_NE(one.view("upper").pixels, other.view("upper").pixels);
}

}  // namespace
}  // namespace portalsim

namespace portalsim {
namespace {

// The sparse features path (tables + overlap pixels) against the dense one (full images,
// then pooling): the same numbers to the bit, for every block size and noise setting.
TEST(SparseFeatures, EqualDenseToTheBit) {
  std::vector<Scenario> scenes;
  const Catalogue& c = test::catalogue();
  for (size_t var = 0; var < c.variant_list.size(); ++var)
    for (int r = 0; r < kBuiltinRegions; ++r) {
      Scenario s;
      s.subject = static_cast<int>((var * 7 + r) % c.subjects.size());
      s.objects[r] = static_cast<int16_t>(var);
      scenes.push_back(s);
    }
  for (uint64_t k = 0; k < 600; ++k) scenes.push_back(test::random_scenario(c, k, k % 3 == 0 ? 13 : 4));
  Scenario crowded;  // every region full: overlaps of three and more footprints
  for (int r = 0; r < kBuiltinRegions; ++r) crowded.objects[r] = static_cast<int16_t>(r % c.variant_list.size());
  scenes.push_back(crowded);
  scenes.push_back(Scenario());
  auto cl = make_opencl_backend(c, test::assets(), test::runtime());
  for (int block : {10, 7, 1, 20, 200}) {
    for (bool noise : {true, false}) {
      Plan p;
      p.images = 0;
      p.model.block = block;
      p.model.pattern_noise = noise;
      p.model.seed = 4242;
      BatchOutput sparse, dense;
      ASSERT_EQ(test::features_path(*cl, p), "thesis_sparse_features");
      cl->run(test::batch_of(scenes, 3), p, sparse);
      p.fidelity.pooling = Pooling::dense;
      ASSERT_EQ(test::features_path(*cl, p), Backend::kPooledFeatures);
      cl->run(test::batch_of(scenes, 3), p, dense);
      ASSERT_EQ(sparse.features.size(), dense.features.size());
      size_t mismatches = 0;
      for (size_t k = 0; k < dense.features.size(); ++k) mismatches += sparse.features[k] != dense.features[k];
      EXPECT_EQ(mismatches, 0u) << "block " << block << " noise " << noise;
      EXPECT_EQ(sparse.metal, dense.metal);
    }
  }
}

}  // namespace
}  // namespace portalsim

namespace portalsim {
namespace {

// Sprite placement with jitter, whole-pixel and sub-pixel (bilinear): kernels within the
// standard tier's tolerance of the reference, and the sprites really move.
TEST(Parity, PlacementJitterIntegerAndBilinear) {
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 150; ++k) scenes.push_back(test::random_scenario(test::catalogue(), k, 6));
  auto cl = make_opencl_backend(test::catalogue(), test::assets(), test::runtime());
  auto ref = make_reference_backend(test::catalogue(), test::assets());
  BatchOutput still;
  Plan p;
  p.model.seed = 31;
  cl->run(test::batch_of(scenes), p, still);
  for (bool bilinear : {false, true}) {
    p.model.bilinear = bilinear;
    p.model.jitter = 4.5;
    ASSERT_NE(test::features_path(*cl, p), "thesis_sparse_features");
    BatchOutput a, b;
    cl->run(test::batch_of(scenes), p, a);
    ref->run(test::batch_of(scenes), p, b);
    const OutputDiff d = compare_outputs(a, b);
    EXPECT_EQ(check_tolerance(d, tier_tolerance(Tier::standard)), "") << "bilinear " << bilinear;
    EXPECT_NE(a.view("upper").pixels, still.view("upper").pixels) << "jitter must move the sprites";
    EXPECT_EQ(a.metal, still.metal) << "placement does not touch the metal detector";
  }
  // Bilinear placement without jitter still samples between texels only at whole pixels:
  // it equals integer placement to within a level.
  p.model.jitter = 0;
  p.model.bilinear = true;
  BatchOutput c;
  cl->run(test::batch_of(scenes), p, c);
  EXPECT_LE(compare_outputs(c, still).of(Camera::mmw).max_abs, 1);
}

}  // namespace
}  // namespace portalsim

namespace portalsim {
namespace {

// Helpers both backends call (docs/dev/testing.md, "Shared helpers"), against values
// worked out by hand from the catalogue: a shared mistake here would pass every parity test.

// Catalogue::polarizability: the category's mean m spread as m 3 / (a + 2) across and
// a times that along the drawing's long axis (x, or z for a "v" drawing).
TEST(SharedHelpers, PolarizabilityHandComputed) {
  const Catalogue& c = catalogue();
  struct Case {
    const char* object;
    int drawing;           // index among the object's drawings
    double along, across;  // cm^3
    int axis;              // 0 x, 2 z
  };
  // gun: heavy 100, anisotropy 1.6; iron-rod: large 322.24, 13.9; compact-disk: trace 13.475, 1.
  for (const Case& k : {Case{"gun", 0, 300 / 3.6 * 1.6, 300 / 3.6, 0}, Case{"gun", 1, 300 / 3.6 * 1.6, 300 / 3.6, 2},
                        Case{"iron-rod", 1, 322.24 * 3 / 15.9 * 13.9, 322.24 * 3 / 15.9, 2},
                        Case{"compact-disk", 0, 13.475, 13.475, 0}}) {
    SCOPED_TRACE(std::string(k.object) + " drawing " + std::to_string(k.drawing));
    const std::array<double, 9> t = c.polarizability(test::variant_of(c, k.object) + k.drawing);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double want = i != j ? 0.0 : i == k.axis ? k.along : k.across;
        EXPECT_NEAR(t[i * 3 + j], want, 1e-12 * std::max(1.0, want)) << i << "," << j;
      }
  }
  EXPECT_EQ(c.polarizability(test::variant_of(c, "ceramic-plate")), (std::array<double, 9>{}));  // metal "none"
}

// Sensor::place: region r's rectangle moved down round((1 - height) (floor_row - c)) rows,
// c its centre row; floor_row is 400 for the upper MMW view (one view below), 200 for the
// lower view and the IR view. Heights 0.875 and 1.125 are exact in binary.
TEST(SharedHelpers, PlaceHandComputed) {
  std::string text = test::with_subject_line(std::string(embedded::default_catalogue), 0, "height = 0.875");
  text = test::with_subject_line(text, 1, "height = 1.125");
  const Catalogue c = parse_catalogue(text, "test.toml", "", "");
  struct Case {
    const char* view;
    int region, subject;  // 1-based region
    int y;
  };
  // upper r1 [49, 40, 34, 70]: 0.125 (400 - 75) = 40.625 -> 41; lower r7 [48, 5, 34, 65]:
  // 0.125 (200 - 37.5) = 20.3 -> 20; lower r12 [54, 140, 40, 50]: 0.125 * 35 = 4.4 -> 4;
  // IR r1 [24, 20, 17, 35]: 0.125 (200 - 37.5) -> 20; IR r13 [53, 170, 20, 25]: 2.2 -> 2;
  // and the same at 1.125, the other way.
  for (const Case& k : {Case{"upper", 1, 0, 81}, Case{"lower", 7, 0, 25}, Case{"lower", 12, 0, 144},
                        Case{"ir", 1, 0, 40}, Case{"ir", 13, 0, 172}, Case{"upper", 1, 1, -1},
                        Case{"lower", 12, 1, 136}, Case{"ir", 13, 1, 168}, Case{"upper", 1, 2, 40}}) {
    SCOPED_TRACE(std::string(k.view) + " region " + std::to_string(k.region) + " subject " + std::to_string(k.subject));
    const Sensor& s = c.sensors[c.sensor_index(k.view)];
    const Rect r = s.place(k.subject, k.region - 1);
    EXPECT_EQ(r.y, k.y);
    EXPECT_EQ(r.x, s.rects[k.region - 1].x);
    EXPECT_EQ(r.w, s.rects[k.region - 1].w);
    EXPECT_EQ(r.h, s.rects[k.region - 1].h);
  }
}

// FeatureLayout::of: ceil(200 / block) blocks a side in each of the two MMW views, then the
// 13 regions.
TEST(SharedHelpers, FeatureLayoutHandComputed) {
  for (auto [block, side] : {std::pair{10, 20}, std::pair{7, 29}, std::pair{1, 200}, std::pair{300, 1}}) {
    const FeatureLayout f = FeatureLayout::of(catalogue(), block);
    EXPECT_EQ(f.grids[0].blocks_x, side);
    EXPECT_EQ(f.grids[0].blocks_y, side);
    EXPECT_EQ(f.image_features(), 2 * side * side + 13);
  }
}

// The tolerance table in docs/dev/testing.md is plan/tolerance.h's. After changing the
// table, regenerate the page's copy: PORTALSIM_UPDATE_GOLDEN=1 build/portalsim_tests
// --gtest_filter='Tolerance.*'.
TEST(Tolerance, TestingPageHoldsTheTable) {
  const std::string path = std::string(PORTALSIM_SOURCE_DIR) + "/docs/dev/testing.md";
  const std::string begin = "<!-- tolerance table: generated from host/plan/tolerance.h -->\n", end = "<!-- end -->";
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string page = ss.str();
  const size_t a = page.find(begin);
  size_t b = page.find(end, a == std::string::npos ? 0 : a);
  ASSERT_NE(a, std::string::npos) << path << ": no \"" << begin << "\"";
  ASSERT_NE(b, std::string::npos) << path << ": no \"" << end << "\" after the table";
  const std::string table = tolerance_table_markdown();
  if (const char* u = std::getenv("PORTALSIM_UPDATE_GOLDEN"); u && std::string(u) == "1") {
    page.replace(a + begin.size(), b - a - begin.size(), table);
    std::ofstream(path) << page;
    b = a + begin.size() + table.size();
  }
  EXPECT_EQ(page.substr(a + begin.size(), b - a - begin.size()), table)
      << path << " differs from plan/tolerance.h; regenerate it (see this test)";
  // No bound is the whole range, and every (model, tier, output) has a row.
  for (const Bound& bound : kTolerances) EXPECT_LT(bound.max_abs, 255) << output_name(bound.output);
  for (Model m : {Model::thesis, Model::physics})
    for (Tier t : {Tier::exact, Tier::standard, Tier::fast})
      for (Output o : {Output::pixels, Output::features, Output::features_only, Output::metal, Output::masks})
        EXPECT_STRNE(tolerance_bound(m, t, o).reason, "no row: nothing may differ") << output_name(o);
}

}  // namespace
}  // namespace portalsim
