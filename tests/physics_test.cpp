// The physics model (--model physics): parity of the MMW chain's kernels with the fp64
// reference, and the physical invariants that fail when the physics is wrong: the PSF's
// width, the noise level through the display, no detail finer than the raw grid, the sign
// and size of metal's contrast, and the extremes.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <numbers>

#include "assets/image_io.h"
#include "backend/compare.h"
#include "backend/opencl/raw_grid_pooling.h"
#include "backend/reference/draws.h"
#include "backend/reference/stages.h"
#include "backend/stages.h"
#include "base/embedded.h"
#include "base/error.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "support.h"

namespace portalsim {
namespace {

namespace fs = std::filesystem;

using test::assets;
using test::catalogue;
using test::physics_plan;
using test::variant_of;

std::vector<Scenario> scenes(size_t n) {
  std::vector<Scenario> v;
  for (size_t k = 0; k < n; ++k) v.push_back(test::random_scenario(catalogue(), k, 6));
  return v;
}

// The Airy core's FWHM in view pixels, from the catalogue's camera, written out here.
double fwhm_formula(const Catalogue& cat, int width) {
  const PhysicsConfig& pc = cat.physics;
  const double lambda = 299792458.0 / (pc.frequency_ghz * 1e9);
  return 1.02 * lambda / pc.aperture_m * pc.range_m / (2 * pc.range_m * std::tan(pc.fov_rad / 2) / width);
}

constexpr size_t kCoverage = 240;

// The coverage set (support.h: every variant in every region, then crowds of up to 6).
std::vector<Scenario> coverage_set(size_t n) { return test::parity_set(catalogue(), n, 6); }

// The tiers on the coverage set; the placements and raw grids on its first 48 (the first
// drawings in every region), to keep the fp64 reference's time in bounds.
TEST(Physics, KernelsMatchTheReferenceInEveryTier) {
  const std::vector<Scenario> all = coverage_set(kCoverage);
  const SceneBatch batch = test::batch_of(all), first = test::batch_of({all.begin(), all.begin() + 48});
  auto ref = make_reference_backend(catalogue(), assets());
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  struct Case {
    const char* name;
    Tier tier;
    double jitter;
    bool bilinear;
    int raw;
  };
  for (const Case& c : {Case{"standard", Tier::standard, 0, false, 28}, Case{"exact", Tier::exact, 0, false, 28},
                        Case{"fast", Tier::fast, 0, false, 28}, Case{"jitter", Tier::standard, 6, false, 28},
                        Case{"bilinear", Tier::standard, 6, true, 28}, Case{"raw 200", Tier::standard, 0, false, 200},
                        Case{"raw 1", Tier::standard, 0, false, 1}, Case{"raw 37x13", Tier::standard, 0, false, -1}}) {
    SCOPED_TRACE(c.name);
    Plan plan = physics_plan();
    plan.fidelity = tier_fidelity(c.tier);
    plan.model.jitter = c.jitter;
    plan.model.bilinear = c.bilinear;
    plan.model.raw_width = c.raw > 0 ? c.raw : 37;
    plan.model.raw_height = c.raw > 0 ? c.raw : 13;
    const SceneBatch& b = c.jitter == 0 && c.raw == 28 ? batch : first;
    BatchOutput r, k;
    ref->run(b, plan, r);
    cl->run(b, plan, k);
    const OutputDiff d = compare_outputs(k, r);
    // The tolerance table (plan/tolerance.h), and the MMW camera's own: pixels within 1
    // gray level, at most 0.5% of them off by one; metal zones exact.
    EXPECT_EQ(check_tolerance(d, model_tolerance(Model::physics, c.tier)), "");
    test::expect_camera_parity(d.of(Camera::mmw));
    EXPECT_EQ(d.metal_exact, 1.0);
  }
}

// The fast tier's draws (Plan::physics_draws_approximated): the MMW frames as one draw of
// NETD / sqrt(frames), every MMW and IR draw an Irwin-Hall one, which the reference draws
// its own way (reference/draws.cpp, fast_gaussian). All three views with noise against the
// reference value by value: ten frames, and an IR NETD (0.5 K) at which a wrong draw moves
// most IR pixels by several levels. The draws follow --noise-draw alone, as the thesis
// model's do: the standard tier with irwin-hall draws them too (its frames one by one).
TEST(Physics, FastTierDrawsMatchTheReference) {
  const SceneBatch batch = test::batch_of(coverage_set(48));
  Plan standard = physics_plan();
  standard.model.frames = 10;
  standard.model.ir_netd = 0.5;
  Plan fast = standard, standard_ih = standard;
  fast.fidelity = tier_fidelity(Tier::fast);
  standard_ih.fidelity.draw = NoiseDraw::irwin_hall;
  ASSERT_TRUE(fast.physics_draws_approximated() && standard_ih.physics_draws_approximated());
  ASSERT_FALSE(standard.physics_draws_approximated());
  BatchOutput box_muller;
  make_opencl_backend(catalogue(), assets(), test::runtime())->run(batch, standard, box_muller);
  for (const Plan* plan : {&fast, &standard_ih}) {
    SCOPED_TRACE(plan == &fast ? "fast tier" : "standard tier, noise_draw irwin-hall");
    BatchOutput r, k;
    make_reference_backend(catalogue(), assets())->run(batch, *plan, r);
    make_opencl_backend(catalogue(), assets(), test::runtime())->run(batch, *plan, k);
    const OutputDiff d = compare_outputs(k, r);
    EXPECT_EQ(check_tolerance(d, model_tolerance(Model::physics, Tier::fast)), "");
    EXPECT_GT(d.of(Camera::ir).pixels, 0u);
    test::expect_camera_parity(d.of(Camera::mmw));
    test::expect_camera_parity(d.of(Camera::ir));
    EXPECT_NE(k.view("ir").pixels, box_muller.view("ir").pixels) << "the draws must not be the table's";
  }
}

// The fast draw itself (the reference's, which the test above holds the kernels to): over
// 2^20 cells, mean 0 and sd 1 within 0.5%, |g| <= 3.365, excess kurtosis near the
// quintic's -0.010, and within 0.006 of the normal in Kolmogorov-Smirnov distance (the
// distribution's own is 0.0033; 2^20 draws add about 0.0013).
TEST(Physics, FastDrawsAreNearlyNormal) {
  std::vector<double> g;
  for (int p = 0; p < (1 << 20); ++p) g.push_back(reference::fast_gaussian(7, 3, kStreamIrNoise, 2, p));
  double m = 0, m2 = 0, m4 = 0, top = 0;
  for (double v : g) m += v, top = std::max(top, std::fabs(v));
  m /= double(g.size());
  for (double v : g) m2 += (v - m) * (v - m), m4 += std::pow(v - m, 4);
  m2 /= double(g.size()), m4 /= double(g.size());
  EXPECT_NEAR(m, 0, 0.005);
  EXPECT_NEAR(std::sqrt(m2), 1, 0.005);
  EXPECT_LE(top, 3.365);
  EXPECT_NEAR(m4 / (m2 * m2) - 3, -0.010, 0.03);
  const SampleComparison c = compare_samples(g);
  EXPECT_LT(c.ks, 0.006);
  EXPECT_GT(c.ks, 0.001);  // not the table's normal: it is the approximation
}

// Features-only runs in every tier against the reference at NETD 0 (rounding only), on the
// coverage set: the fast tier's is the raw-grid path (backend/opencl/raw_grid_pooling.h),
// held to its row of the tolerance table; the others pool the dense path's images.
TEST(Physics, FeaturesOnlyRunsMatchTheReferenceAtNetdZero) {
  const SceneBatch batch = test::batch_of(coverage_set(kCoverage));
  auto ref = make_reference_backend(catalogue(), assets());
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (double jitter : {0.0, 3.5}) {
    Plan plan = physics_plan();
    plan.model.netd = 0;
    plan.model.jitter = jitter;
    BatchOutput r;
    ref->run(batch, plan, r);
    for (Tier tier : {Tier::exact, Tier::standard, Tier::fast}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + ", jitter " + std::to_string(jitter));
      Plan features = plan;
      features.images = 0;
      features.fidelity = tier_fidelity(tier);
      ASSERT_EQ(test::features_path(*cl, features) == "physics_raw_features", tier == Tier::fast);
      BatchOutput k;
      cl->run(batch, features, k);
      const OutputDiff d = compare_outputs(k, r);
      ASSERT_TRUE(d.features_only);
      EXPECT_EQ(check_tolerance(d, model_tolerance(Model::physics, tier)), "");
    }
  }
}

// The raw-grid path's features column by column, at NETD 0 on the coverage set: each
// feature's mean error over the scenarios (its bias) is held to the table's row for it.
// The table's mean over all values cannot see an offset on a few columns: the 13 region
// features are 13 of 813.
TEST(Physics, RawGridFeaturesHaveNoBiasColumnByColumn) {
  // The whole set under the sanitizers too: a mean over fewer scenarios is another bound.
  const SceneBatch batch = test::batch_of(test::coverage(catalogue(), kCoverage, 6));
  auto ref = make_reference_backend(catalogue(), assets());
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  Plan plan = physics_plan();
  plan.model.netd = 0;
  BatchOutput r, k;
  ref->run(batch, plan, r);
  Plan features = plan;
  features.images = 0;
  features.fidelity = tier_fidelity(Tier::fast);
  ASSERT_EQ(test::features_path(*cl, features), "physics_raw_features");
  cl->run(batch, features, k);
  ASSERT_EQ(k.features.size(), r.features.size());
  const size_t n = r.n, columns = static_cast<size_t>(r.layout.image_features());
  ASSERT_EQ(r.features.size(), n * columns);
  const std::vector<std::string> names = r.layout.names();
  const Bound& bound = tolerance_bound(Model::physics, Tier::fast, Output::features_only_bias);
  double worst = 0, mean = 0;
  std::string worst_name;
  for (size_t c = 0; c < columns; ++c) {
    double bias = 0;
    for (size_t i = 0; i < n; ++i) bias += (double(k.features[i * columns + c]) - r.features[i * columns + c]) / n;
    mean += std::abs(bias) / columns;
    if (std::abs(bias) > worst) worst = std::abs(bias), worst_name = names[c];
  }
  EXPECT_LE(worst, bound.max_abs) << worst_name;
  EXPECT_LE(mean, bound.mean_abs);
}

// The raw-grid path's NETD, drawn per feature, against the reference's per raw pixel:
// other draws, so statistically. For each feature whose noise-free value the window does
// not clamp, z = (kernel - reference - (their noise-free difference)) / (sd sqrt 2), sd the
// feature's standard deviation under per-raw-pixel noise (RawGridNoise::covariance
// through the window), must be N(0, 1): mean, sd and KS distance. Features are taken
// every third block along each axis, so that neighbours sharing raw cells do not make
// the sample's values dependent. Per value and on average, |kernel - reference| is held
// to the table's multiples of sd sqrt 2 over the noise-free bound.
TEST(Physics, RawGridFeatureNoiseMatchesTheReference) {
  const SceneBatch batch = test::batch_of(coverage_set(kCoverage));
  auto ref = make_reference_backend(catalogue(), assets());
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  Plan plan = physics_plan(11);
  plan.metal = false;
  plan.fidelity = tier_fidelity(Tier::fast);
  Plan quiet = plan;
  quiet.model.netd = 0;
  BatchOutput r, r0, k, k0;
  ref->run(batch, plan, r);
  ref->run(batch, quiet, r0);
  plan.images = quiet.images = 0;
  ASSERT_EQ(test::features_path(*cl, plan), "physics_raw_features");
  cl->run(batch, plan, k);
  cl->run(batch, quiet, k0);
  const FeatureLayout& lay = k.layout;
  const size_t row = lay.image_features();
  ASSERT_EQ(r.features.size(), k.features.size());
  const double scale = 255.0 / (plan.model.window_hi - plan.model.window_lo);
  const Bound& clean = tolerance_bound(Model::physics, Tier::fast, Output::features_only);
  const Bound& noisy = tolerance_bound(Model::physics, Tier::fast, Output::features_only_noisy);
  std::vector<double> z;
  double sum_abs = 0, sum_sd = 0;
  size_t over = 0, values = 0;
  for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
    const RawGridPooling pool = raw_grid_pooling(catalogue().sensors[lay.pooled[slot]], lay, static_cast<int>(slot),
                                                 plan.model.raw_width, plan.model.raw_height);
    for (int f = 0; f < lay.grids[0].blocks(); ++f) {
      const size_t col = static_cast<size_t>(pool.columns[f]);
      const double sd = plan.model.netd * scale * std::sqrt(2 * RawGridNoise::covariance(pool, f, f));
      const bool spaced = (f % lay.grids[0].blocks_x) % 3 == 0 && (f / lay.grids[0].blocks_x) % 3 == 0;
      for (size_t i = 0; i < batch.size(); ++i) {
        const size_t at = i * row + col;
        const double c0 = k0.features[at];
        if (c0 < 20 || c0 > 235 || sd <= 0) continue;  // the window may clamp
        const double e = double(k.features[at]) - r.features[at];
        over += std::abs(e) > clean.max_abs + noisy.max_abs * sd;
        sum_abs += std::abs(e);
        sum_sd += sd;
        ++values;
        if (spaced) z.push_back((e - (c0 - r0.features[at])) / sd);
      }
    }
  }
  ASSERT_GT(z.size(), 1000u);
  const SampleComparison d = compare_samples(z);
  const double n = double(z.size());
  EXPECT_NEAR(d.mean_a, 0.0, 4 / std::sqrt(n));
  EXPECT_NEAR(d.sd_a, 1.0, 4 / std::sqrt(2 * n));
  EXPECT_LE(d.ks, d.ks_critical);
  EXPECT_EQ(over, 0u) << "features beyond " << noisy.max_abs << " sd of the reference";
  EXPECT_LE(sum_abs / values, clean.mean_abs + noisy.mean_abs * sum_sd / values);
}

// Features-only runs under the block-mean noise model (the fast tier) take the raw-grid
// path (backend/opencl/raw_grid_pooling.h). Without sensor noise, stated tolerance against
// the dense path (the same tier, --pooling dense): only per-pixel rounding is left out, so
// every feature is within 0.5 of a level, whether a scenario's features come from the
// object tables or from its raw grid (jitter and overlapping objects take the raw grid).
TEST(Physics, RawGridFeaturesMatchTheDensePath) {
  const SceneBatch batch = test::batch_of(scenes(300));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (double jitter : {0.0, 3.5}) {
    SCOPED_TRACE("jitter " + std::to_string(jitter));
    Plan plan = physics_plan();
    plan.images = 0;
    plan.metal = false;
    plan.model.netd = 0;
    plan.model.jitter = jitter;
    plan.fidelity = tier_fidelity(Tier::fast);
    ASSERT_EQ(test::features_path(*cl, plan), "physics_raw_features");
    Plan dense = plan;
    dense.fidelity.pooling = Pooling::dense;
    ASSERT_EQ(test::features_path(*cl, dense), Backend::kPooledFeatures);
    BatchOutput a, b;
    cl->run(batch, plan, a);
    cl->run(batch, dense, b);
    ASSERT_EQ(a.features.size(), b.features.size());
    const double max_abs = compare_outputs(a, b).feature_max_abs;
    EXPECT_LE(max_abs, 0.5);
    EXPECT_GT(max_abs, 0.0) << "the raw-grid path leaves rounding out: it cannot equal the dense path";
  }
}

// The raw-grid path draws the NETD's noise per feature, not per raw pixel: each feature's
// variance and each pair's covariance must be what per-raw-pixel noise gives through the
// display (RawGridNoise::covariance, in gray levels through the window). 6,000 scenarios
// of one scene; tolerance 6% on variances and 0.06 on correlations (sampling error about
// 2% and 0.013); features clamped by the window at NETD 0 are left out. Cases: the
// default; a 1x1 raw grid (every feature the same cell: singular Gram matrices); blocks
// of 3 pixels (a work space too large for private memory, in chunked launches).
TEST(Physics, RawGridNoiseHasThePerPixelCovariance) {
  const size_t n = 6000;
  std::vector<Scenario> v(n, scenes(1)[0]);
  const SceneBatch batch = test::batch_of(v);
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  struct Case {
    int raw, block;
  };
  for (const Case c : {Case{28, 10}, Case{1, 10}, Case{28, 3}}) {
    SCOPED_TRACE("raw grid " + std::to_string(c.raw) + ", block " + std::to_string(c.block));
    Plan plan = physics_plan();
    plan.images = 0;
    plan.metal = false;
    plan.fidelity = tier_fidelity(Tier::fast);
    plan.model.raw_width = plan.model.raw_height = c.raw;
    plan.model.block = c.block;
    Plan quiet = plan;
    quiet.model.netd = 0;
    BatchOutput noisy, clean;
    cl->run(batch, plan, noisy);
    cl->run(batch, quiet, clean);
    const FeatureLayout lay = noisy.layout;
    const Sensor& upper = catalogue().sensors[lay.pooled[0]];
    const RawGridPooling pool = raw_grid_pooling(upper, lay, 0, c.raw, c.raw);
    const double scale = 255.0 / (plan.model.window_hi - plan.model.window_lo);
    const double sd2 = plan.model.netd * plan.model.netd * scale * scale;
    const size_t row = lay.image_features();
    const auto column = [&](int f) { return static_cast<size_t>(pool.columns[f]); };
    // Some blocks, their right and lower neighbours, and the last region the view sees.
    const int blocks = lay.grids[0].blocks(), region = static_cast<int>(pool.columns.size()) - 1;
    std::vector<std::pair<int, int>> pairs;
    for (int f = 0; f < blocks; f += blocks / 11 + 1) {
      pairs.emplace_back(f, f);
      if (f + 1 < blocks) pairs.emplace_back(f, f + 1);
      if (f + lay.grids[0].blocks_x < blocks) pairs.emplace_back(f, f + lay.grids[0].blocks_x);
      pairs.emplace_back(f, region);
    }
    pairs.emplace_back(region, region);
    size_t checked = 0;
    for (const auto& [f, g] : pairs) {
      const double cf = clean.features[column(f)], cg = clean.features[column(g)];
      if (cf < 20 || cf > 235 || cg < 20 || cg > 235) continue;
      double sf = 0, sg = 0, sfg = 0, sff = 0, sgg = 0;
      for (size_t i = 0; i < n; ++i) {
        const double x = noisy.features[i * row + column(f)] - cf, y = noisy.features[i * row + column(g)] - cg;
        sf += x, sg += y, sfg += x * y, sff += x * x, sgg += y * y;
      }
      const double cov = sfg / n - sf / n * sg / n, vf = sff / n - sf * sf / n / n, vg = sgg / n - sg * sg / n / n;
      const double want = RawGridNoise::covariance(pool, f, g), want_f = RawGridNoise::covariance(pool, f, f),
                   want_g = RawGridNoise::covariance(pool, g, g);
      SCOPED_TRACE("features " + std::to_string(f) + ", " + std::to_string(g));
      EXPECT_NEAR(vf / (sd2 * want_f), 1.0, 0.06);
      EXPECT_NEAR(cov / std::sqrt(vf * vg), want / std::sqrt(want_f * want_g), 0.06);
      ++checked;
    }
    EXPECT_GE(checked, 10u);
  }
}

// The declared fast path (physics_raw, then mmw_display) against the chain of stage
// kernels: within 1 gray level, at most 0.5% of pixels off by one (the raw grid is summed
// in another order), in every tier and placement.
TEST(Physics, FastPathMatchesTheChainOfStageKernels) {
  const SceneBatch batch = test::batch_of(coverage_set(kCoverage));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (Tier tier : {Tier::fast, Tier::standard, Tier::exact})
    for (bool bilinear : {false, true}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (bilinear ? " bilinear" : ""));
      Plan plan = physics_plan();
      plan.fidelity = tier_fidelity(tier);
      plan.model.jitter = 5;
      plan.model.bilinear = bilinear;
      BatchOutput fast, staged;
      cl->run(batch, plan, fast);
      plan.fidelity.fused = false;
      cl->run(batch, plan, staged);
      const OutputDiff d = compare_outputs(fast, staged);
      test::expect_camera_parity(d.of(Camera::mmw));
    }
}

// Each stage of the chain changes the image, in both backends alike.
TEST(Physics, EachStageOfTheChainDoesSomethingInBothBackends) {
  const SceneBatch batch = test::batch_of(scenes(16));
  Plan plan = physics_plan();
  plan.fidelity.fused = false;
  BatchOutput whole;
  make_reference_backend(catalogue(), assets())->run(batch, plan, whole);
  for (const std::string dropped : {"optics", "netd"}) {
    SCOPED_TRACE(dropped);
    Catalogue cat = catalogue();
    for (Sensor& s : cat.sensors)
      if (s.camera == Camera::mmw) std::erase(s.physics_chain, dropped);
    BatchOutput r, k;
    make_reference_backend(cat, assets())->run(batch, plan, r);
    make_opencl_backend(cat, assets(), test::runtime())->run(batch, plan, k);
    const OutputDiff d = compare_outputs(k, r);
    EXPECT_LE(d.of(Camera::mmw).max_abs, 1);
    EXPECT_NE(r.view("upper").pixels, whole.view("upper").pixels) << "the stage changes nothing";
  }
}

TEST(Physics, TheModelKnobSwitchesEveryCamerasChain) {
  const SceneBatch batch = test::batch_of(scenes(8));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  BatchOutput thesis, physics;
  cl->run(batch, Plan{}, thesis);
  cl->run(batch, physics_plan(0), physics);
  EXPECT_NE(thesis.view("upper").pixels, physics.view("upper").pixels);
  EXPECT_NE(thesis.view("lower").pixels, physics.view("lower").pixels);
  EXPECT_NE(thesis.view("ir").pixels, physics.view("ir").pixels);
}

TEST(Physics, OutputDoesNotDependOnTheBatch) {
  const std::vector<Scenario> all = scenes(40);
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const Plan plan = physics_plan(3);
  BatchOutput whole, a, b;
  cl->run(test::batch_of(all), plan, whole);
  cl->run(test::batch_of({all.begin(), all.begin() + 17}), plan, a);
  cl->run(test::batch_of({all.begin() + 17, all.end()}, 17), plan, b);
  append_output(a, b);
  EXPECT_EQ(whole.view("upper").pixels, a.view("upper").pixels);
  EXPECT_EQ(whole.features, a.features);
}

// The PSF's FWHM, measured on a point source through the reference's optics stage, is
// the Airy core's 1.02 lambda / D within 5%.
TEST(Physics, PointSpreadFunctionWidthMatchesTheFormula) {
  const Catalogue& cat = catalogue();
  const Plan plan = physics_plan();
  const Sensor& upper = cat.sensors[0];
  const double expected = fwhm_formula(cat, upper.width);
  EXPECT_NEAR(reference::psf_fwhm_pixels(cat, upper), expected, 1e-9 * expected);
  // Vela 125: about 2 raw pixels of 28 (the figure).
  EXPECT_NEAR(expected / (upper.width / 28.0), 1.7, 0.2);
  Scenario s;
  const reference::ViewScene vs = reference::view_scene(cat, assets(), plan.model, 0, s, 0);
  reference::Field f;
  f.width = upper.width;
  f.height = upper.height;
  f.v.assign(upper.pixels(), 0.0);
  f.at(100, 100) = 1.0;
  reference::optics(vs, f);
  const double peak = f.at(100, 100);
  int x = 100;
  while (f.at(x + 1, 100) >= peak / 2) ++x;
  const double right = x + (f.at(x, 100) - peak / 2) / (f.at(x, 100) - f.at(x + 1, 100));
  const double measured = 2 * (right - 100);
  EXPECT_NEAR(measured, expected, 0.05 * expected);
}

// Sum of the squared bilinear weights of view pixel x on a raw axis (the display's).
double weight_squares(int x, int size, int raw) {
  const double u = std::clamp((x + 0.5) * raw / size - 0.5, 0.0, raw - 1.0);
  const double t = u - std::floor(u);
  return (1 - t) * (1 - t) + t * t;
}

// On the same scene, two seeds' images differ by the noise alone: their variance matches
// NETD through the display (window scale and bilinear weights) within 5%.
TEST(Physics, NoiseMatchesTheNetdThroughTheDisplay) {
  const Catalogue& cat = catalogue();
  auto cl = make_opencl_backend(cat, assets(), test::runtime());
  const std::vector<Scenario> scene(1, test::random_scenario(cat, 3, 2));
  const Plan plan = physics_plan();
  const double scale = 255.0 / (plan.model.window_hi - plan.model.window_lo);
  for (int raw : {28, 200}) {
    SCOPED_TRACE(raw);
    double measured = 0, expected = 0;
    const int pairs = 8;
    for (int k = 0; k < pairs; ++k) {
      BatchOutput a, b;
      Plan plan = physics_plan(100 + 2 * k);
      plan.model.netd = 1.0;
      plan.model.raw_width = plan.model.raw_height = raw;
      cl->run(test::batch_of(scene), plan, a);
      plan.model.seed += 1;
      cl->run(test::batch_of(scene), plan, b);
      for (const char* view : {"upper", "lower"}) {
        const ViewImages& va = a.view(view);
        const ViewImages& vb = b.view(view);
        for (int y = 0; y < va.height; ++y)
          for (int x = 0; x < va.width; ++x) {
            const double d = double(va.pixels[y * va.width + x]) - vb.pixels[y * va.width + x];
            measured += d * d / 2;
            // Rounding adds 1/12 of a gray level squared per image.
            expected += scale * scale * weight_squares(x, va.width, raw) * weight_squares(y, va.height, raw) + 1.0 / 12;
          }
      }
    }
    EXPECT_NEAR(measured / expected, 1.0, 0.05);
  }
}

// The DFT power of an image above a raw grid's Nyquist limit, as a share of all but DC.
double share_above_nyquist(const std::vector<double>& img, int w, int h, int raw_w, int raw_h) {
  std::vector<std::complex<double>> a(img.size());
  double mean = 0;
  for (double v : img) mean += v;
  mean /= img.size();
  for (size_t k = 0; k < img.size(); ++k) a[k] = img[k] - mean;
  const auto dft = [](std::vector<std::complex<double>>& line) {
    const size_t n = line.size();
    std::vector<std::complex<double>> out(n);
    for (size_t k = 0; k < n; ++k)
      for (size_t j = 0; j < n; ++j) out[k] += line[j] * std::polar(1.0, -2 * std::numbers::pi * double(k * j % n) / n);
    line = out;
  };
  for (int y = 0; y < h; ++y) {
    std::vector<std::complex<double>> row(a.begin() + y * w, a.begin() + (y + 1) * w);
    dft(row);
    std::copy(row.begin(), row.end(), a.begin() + y * w);
  }
  for (int x = 0; x < w; ++x) {
    std::vector<std::complex<double>> col(h);
    for (int y = 0; y < h; ++y) col[y] = a[y * w + x];
    dft(col);
    for (int y = 0; y < h; ++y) a[y * w + x] = col[y];
  }
  double above = 0, total = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int fx = std::min(x, w - x), fy = std::min(y, h - y);  // cycles per view
      const double p = std::norm(a[y * w + x]);
      total += p;
      if (2 * fx > raw_w || 2 * fy > raw_h) above += p;
    }
  return above / total;
}

// No detail finer than the raw grid. Before sampling, the PSF has already removed what
// lies above the raw grid's Nyquist limit (at most 1% of the power is left there, so the
// raw grid carries the whole signal). After display, what lies above it comes from the
// bilinear interpolation alone: the stored image has the share the interpolated raw grid
// has, within 0.5 points (rounding), stated as at most 6%.
TEST(Physics, NoDetailFinerThanTheRawGrid) {
  const Catalogue& cat = catalogue();
  const Scenario s = test::random_scenario(cat, 5, 4);
  const Plan plan = physics_plan();
  const reference::ViewScene vs = reference::view_scene(cat, assets(), plan.model, 0, s, 0);
  reference::Field f;
  reference::radiometry(vs, f);
  const double sharp = share_above_nyquist(f.v, f.width, f.height, 28, 28);
  reference::optics(vs, f);
  const double blurred = share_above_nyquist(f.v, f.width, f.height, 28, 28);
  reference::sample(vs, f);
  reference::netd(vs, f);
  // The display's bilinear interpolation alone, in gray levels but unrounded.
  const double scale = 255.0 / (plan.model.window_hi - plan.model.window_lo);
  std::vector<double> interpolated(200 * 200);
  const auto coord = [](int x, int size, int raw) { return std::clamp((x + 0.5) * raw / size - 0.5, 0.0, raw - 1.0); };
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) {
      const double u = coord(x, 200, 28), v = coord(y, 200, 28);
      const int c0 = int(u), r0 = int(v), c1 = std::min(c0 + 1, 27), r1 = std::min(r0 + 1, 27);
      const double tx = u - c0, ty = v - r0;
      const double t =
          (1 - ty) * ((1 - tx) * f.at(c0, r0) + tx * f.at(c1, r0)) + ty * ((1 - tx) * f.at(c0, r1) + tx * f.at(c1, r1));
      interpolated[y * 200 + x] = (t - plan.model.window_lo) * scale;
    }
  reference::Field shown = f;
  reference::mmw_display(vs, shown);
  const double image = share_above_nyquist(shown.v, shown.width, shown.height, 28, 28);
  const double interpolation = share_above_nyquist(interpolated, 200, 200, 28, 28);
  RecordProperty("share_sharp", std::to_string(sharp));
  RecordProperty("share_blurred", std::to_string(blurred));
  RecordProperty("share_image", std::to_string(image));
  EXPECT_GT(sharp, 3 * blurred) << "the scene before optics has fine detail";
  EXPECT_LE(blurred, 0.01);
  EXPECT_NEAR(image, interpolation, 0.005);
  EXPECT_LE(image, 0.06);
}

// A catalogue whose subject-1 has a flat upper body image (gray = its mmw_level: bare body
// everywhere) and a 120 x 120 metal plate; flat_plan() has a wide display window.
struct FlatWorld {
  test::TempDir dir;
  Catalogue cat;
  AssetSet assets;
  explicit FlatWorld(const std::string& edit_from = "", const std::string& edit_to = "") {
    write_image((dir.w() / "flat.png").string(), Image(200, 200, 1, 150));
    std::string text(embedded::default_catalogue);
    const auto replace = [&](const std::string& from, const std::string& to) {
      const size_t at = text.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      text.replace(at, from.size(), to);
    };
    replace("name = \"subject-1\"\n", "name = \"subject-1\"\nimages.upper = \"flat.png\"\n");
    replace("shape = \"plate\"\nsize = [32, 40]", "shape = \"plate\"\nsize = [120, 120]");
    if (!edit_from.empty()) replace(edit_from, edit_to);
    cat = parse_catalogue(text, "flat.toml", dir.w().string(), "");
    assets = build_assets(cat);
  }
};

Plan flat_plan() {
  Plan plan = physics_plan();
  plan.model.window_lo = 270.0;
  plan.model.window_hi = 350.0;
  return plan;
}

// The raw grid of the upper view, before display (reference stages).
reference::Field raw_grid(const FlatWorld& w, const ModelSettings& m, const Scenario& s) {
  const reference::ViewScene vs = reference::view_scene(w.cat, w.assets, m, 0, s, 0);
  reference::Field f;
  for (const char* stage : {"radiometry", "optics", "sample"}) view_stage(stage).reference(vs, f);
  return f;
}

// Metal reads darker than the body at 293 K illumination and brighter at 330 K, by the
// radiometric formula within 0.5 gray level before rounding (the reference's raw grid) and
// within 1 after (the kernels' image, two rounded values).
TEST(Physics, MetalContrastFollowsTheRadiometricFormula) {
  for (const char* emissivity : {"0.0055", "0.0", "1.0"}) {
    SCOPED_TRACE(emissivity);
    const FlatWorld w("emissivity = 0.0055", std::string("emissivity = ") + emissivity);
    const PhysicsConfig& pc = w.cat.physics;
    const double scale = 255.0 / (flat_plan().model.window_hi - flat_plan().model.window_lo);
    Scenario bare, plate;
    plate.objects[1] = static_cast<int16_t>(variant_of(w.cat, "metal-plate"));  // region 2, centre (100, 75)
    auto cl = make_opencl_backend(w.cat, w.assets, test::runtime());
    for (double illumination : {293.0, 330.0}) {
      SCOPED_TRACE(illumination);
      Plan plan = flat_plan();
      plan.model.illumination = illumination;
      plan.model.netd = 0;
      const double e = std::stod(emissivity), tc = pc.clothing_transmission;
      const double t_metal = pc.skin_temperature - (pc.skin_temperature - pc.room_temperature) *
                                                       std::exp(-plan.model.worn_minutes / 15.0);  // steel
      const double contrast_k =
          tc * ((e * t_metal + (1 - e) * illumination) -
                (pc.skin_emissivity * pc.skin_temperature + (1 - pc.skin_emissivity) * illumination));
      const reference::Field with = raw_grid(w, plan.model, plate), without = raw_grid(w, plan.model, bare);
      const double raw_contrast = with.at(14, 10) - without.at(14, 10);
      EXPECT_NEAR(raw_contrast * scale, contrast_k * scale, 0.5);
      BatchOutput a, b;
      cl->run(test::batch_of({plate}), plan, a);
      cl->run(test::batch_of({bare}), plan, b);
      const double seen = double(a.view("upper").pixels[75 * 200 + 100]) - b.view("upper").pixels[75 * 200 + 100];
      EXPECT_NEAR(seen, contrast_k * scale, 1.0);
      if (e < 0.1) {
        if (illumination < 300)
          EXPECT_LT(seen, -2) << "metal reflects the cooler room: darker than the body";
        else
          EXPECT_GT(seen, 2) << "metal reflects the hotter surroundings: brighter than the body";
      }
    }
  }
}

// Illumination at body temperature, objects warmed to it: no contrast at all.
TEST(Physics, NoContrastWhenEverythingIsAtBodyTemperature) {
  const FlatWorld w;
  Scenario bare, plate;
  plate.objects[1] = static_cast<int16_t>(variant_of(w.cat, "metal-plate"));
  Plan plan = flat_plan();
  plan.model.illumination = w.cat.physics.skin_temperature;
  plan.model.worn_minutes = 1440;
  plan.model.netd = 0;
  auto cl = make_opencl_backend(w.cat, w.assets, test::runtime());
  BatchOutput a, b;
  cl->run(test::batch_of({plate}), plan, a);
  cl->run(test::batch_of({bare}), plan, b);
  int worst = 0;
  for (size_t k = 0; k < a.view("upper").pixels.size(); ++k)
    worst = std::max(worst, std::abs(int(a.view("upper").pixels[k]) - int(b.view("upper").pixels[k])));
  EXPECT_LE(worst, 1);
}

// The automatic window on a grid flatter than PS_WINDOW_MIN_SPAN (1 K between its 1st and
// 99th percentiles): a body filling the view and 0.2 K of noise. The window is then the
// minimum span from the 1st percentile, and the kernels must hold it as the reference does
// (mutation 45 of tools/mutations.txt halves it: twice the contrast).
TEST(Physics, AutoWindowOnAFlatGridKeepsItsMinimumSpan) {
  const FlatWorld w;
  Plan plan = physics_plan();
  plan.model.window_auto = true;
  plan.model.netd = 0.2;
  plan.model.frames = 1;
  const SceneBatch batch = test::batch_of(std::vector<Scenario>(8));
  ASSERT_EQ(batch.at(0).subject, 0) << "subject-1's upper view is the flat one";
  reference::Field raw = raw_grid(w, plan.model, batch.at(0));
  reference::netd(reference::view_scene(w.cat, w.assets, plan.model, 0, batch.at(0), 0), raw);
  std::vector<double> sorted = raw.v;
  std::sort(sorted.begin(), sorted.end());
  const int n = int(sorted.size());
  ASSERT_LT(sorted[size_t(std::lround(0.99 * (n - 1)))] - sorted[size_t(std::lround(0.01 * (n - 1)))], 1.0)
      << "the grid must be flatter than the minimum span";
  for (Tier tier : {Tier::standard, Tier::exact, Tier::fast}) {
    SCOPED_TRACE(tier_name(tier));
    plan.fidelity = tier_fidelity(tier);
    BatchOutput r, k;
    make_reference_backend(w.cat, w.assets)->run(batch, plan, r);
    make_opencl_backend(w.cat, w.assets, test::runtime())->run(batch, plan, k);
    const OutputDiff d = compare_outputs(k, r);
    test::expect_camera_parity(d.of(Camera::mmw));
    const std::vector<uint8_t>& px = k.view("upper").pixels;
    const auto [lo, hi] = std::minmax_element(px.begin(), px.begin() + 200 * 200);
    EXPECT_GT(*hi - *lo, 20) << "the noise must show";
  }
}

TEST(Physics, Extremes) {
  const SceneBatch batch = test::batch_of(scenes(4));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  // NETD 0: no noise, whatever the seed.
  BatchOutput a, b;
  Plan quiet = physics_plan(1);
  quiet.model.netd = 0;
  cl->run(batch, quiet, a);
  quiet.model.seed = 2;
  cl->run(batch, quiet, b);
  EXPECT_EQ(a.view("upper").pixels, b.view("upper").pixels);
  // A 1x1 raw grid: one value over the whole view.
  Plan one = physics_plan();
  one.model.raw_width = one.model.raw_height = 1;
  BatchOutput c;
  cl->run(batch, one, c);
  const std::vector<uint8_t>& px = c.view("upper").pixels;
  for (size_t i = 0; i < 4; ++i)
    EXPECT_TRUE(std::all_of(px.begin() + i * 40000, px.begin() + (i + 1) * 40000,
                            [&](uint8_t v) { return v == px[i * 40000]; }));
  // A PSF wider than the view (a 2 mm aperture): nearly uniform, and the backends agree.
  const FlatWorld w("aperture_m = 0.125", "aperture_m = 0.002");
  EXPECT_GT(reference::psf_fwhm_pixels(w.cat, w.cat.sensors[0]), 200.0);
  Plan wide = flat_plan();
  wide.model.netd = 0;
  BatchOutput r, k;
  Scenario plate;
  plate.objects[1] = static_cast<int16_t>(variant_of(w.cat, "metal-plate"));
  make_reference_backend(w.cat, w.assets)->run(test::batch_of({plate}), wide, r);
  make_opencl_backend(w.cat, w.assets, test::runtime())->run(test::batch_of({plate}), wide, k);
  EXPECT_LE(compare_outputs(k, r).of(Camera::mmw).max_abs, 1);
  const auto [lo, hi] = std::minmax_element(k.view("upper").pixels.begin(), k.view("upper").pixels.end());
  EXPECT_LE(*hi - *lo, 20);
}

// simulate --stages: every stage's field of each view, shaped as the stage leaves it.
TEST(Physics, SimulateWritesEveryStageField) {
  test::TempDir t;
  const auto out = t.w() / "gun";
  const test::Result r =
      test::finish(test::start(t.cap(), {"simulate", "--model", "physics", "--mmw-raw", "28x20", "--stages", "none",
                                         "none", "none", "gun", "--out", out.string()}));
  ASSERT_TRUE(r.exited && r.status == 0) << test::describe(r);
  for (const char* view : {"upper", "lower"}) {
    SCOPED_TRACE(view);
    const std::string v(view);
    EXPECT_NE(test::slurp(out / "stages" / (v + ".1.radiometry.npy")).find("'shape': (200, 200,)"), std::string::npos);
    EXPECT_NE(test::slurp(out / "stages" / (v + ".3.sample.npy")).find("'shape': (20, 28,)"), std::string::npos);
    const std::string shown = test::slurp(out / "stages" / (v + ".6.mmw_display.npy"));
    ASSERT_EQ(shown.size(), 128u + 200 * 200 * 8);
  }
  EXPECT_TRUE(fs::exists(out / "stages" / "ir.1.contact_shadow.npy"));
  EXPECT_TRUE(fs::exists(out / "stages" / "ir.5.ir_display.npy"));
  EXPECT_TRUE(fs::exists(out / "upper.png"));
}

TEST(Physics, BadSettingsAreRefused) {
  Plan p = physics_plan();
  p.model.raw_width = 201;
  EXPECT_THROW(validate(p, catalogue()), InputError);
  Plan q;
  const Knob& raw = *find_knob("mmw_raw");
  for (const char* bad : {"28", "28x", "x28", "0x28", "28x5000", "2.5x3", "-3x4", "28x28x2", "1e1x10", ""})
    EXPECT_THROW(set_knob(q, raw, bad, "--mmw-raw"), InputError) << bad;
  set_knob(q, raw, "40x30", "--mmw-raw");
  EXPECT_EQ(q.model.raw_width, 40);
  EXPECT_EQ(q.model.raw_height, 30);
  // A catalogue without [[materials]] cannot run the physics model.
  std::string text(embedded::default_catalogue);
  text = text.substr(0, text.find("[[materials]]")) + text.substr(text.find("# --- Subjects:"));
  const Catalogue bare = parse_catalogue(text, "bare.toml", "", "");
  EXPECT_TRUE(bare.materials.empty());
  EXPECT_THROW(validate(p, bare), InputError);
  EXPECT_NO_THROW(validate(Plan{}, bare)) << "the thesis model needs no materials";
  // An object naming no known material, a NaN emissivity.
  std::string unknown(embedded::default_catalogue);
  unknown.replace(unknown.find("material = \"cd\""), 14, "material = \"xx\"");
  EXPECT_THROW(parse_catalogue(unknown, "u.toml", "", ""), InputError);
  std::string nan(embedded::default_catalogue);
  nan.replace(nan.find("emissivity = 0.0055"), 19, "emissivity = nan");
  try {
    parse_catalogue(nan, "n.toml", "", "");
    ADD_FAILURE() << "NaN emissivity accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("n.toml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("materials[1].emissivity"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace portalsim
