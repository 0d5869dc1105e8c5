// The physics MMW camera's own processing (docs/model/physics-mmw.md): frame integration
// (netd over --frames), the automatic window (window), the display filter and smoothing
// (mmw_display). Kernels against the fp64 reference; each stage's invariant against its
// formula; the fast tier's one-draw approximation of the frames by its distribution; and
// the defaults' signal-to-noise ratio in both MMW views.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>

#include "backend/compare.h"
#include "backend/reference/stages.h"
#include "backend/stages.h"
#include "base/error.h"
#include "plan/knobs.h"
#include "shared.h"
#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;
using test::physics_plan;

struct Camera {
  const char* name;
  int frames;
  bool window_auto;
  DisplayFilter filter;
  double smooth;
  int raw_width, raw_height;
};

Plan camera_plan(const Camera& c, Tier tier) {
  Plan p = physics_plan();
  p.fidelity = tier_fidelity(tier);
  p.model.frames = c.frames;
  p.model.window_auto = c.window_auto;
  p.model.display_filter = c.filter;
  p.model.smooth = c.smooth;
  p.model.raw_width = c.raw_width;
  p.model.raw_height = c.raw_height;
  return p;
}

// Stated tolerance, as the physics model's (host/plan/tolerance.h): MMW pixels within 1
// gray level, at most 0.5% of them off by one; features within 1. In every tier: the fast
// tier's display (raw rows first) and draws, which the reference follows, included. The
// camera's processing works on whole views, whatever is in them: 24 scenarios of one
// object (the catalogue's first two drawings, region by region) and 24 crowds of up to 6. Every drawing in
// every region is Physics.KernelsMatchTheReferenceInEveryTier's (with this batch, the
// fp64 reference took 65 s of a Release build and 280 s under the sanitizers).
TEST(Camera, KernelsMatchTheReference) {
  // 24 single objects and 24 crowds (6 and 6 under the sanitizers: test::kSanitized).
  const size_t n = test::kSanitized ? 6 : 24;
  std::vector<Scenario> scenarios = test::coverage(catalogue(), 0, 6);
  scenarios.resize(n);
  for (const Scenario& s : test::coverage(catalogue(), n, 6, false)) scenarios.push_back(s);
  const SceneBatch batch = test::batch_of(scenarios);
  auto ref = make_reference_backend(catalogue(), assets());
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto bicubic = DisplayFilter::bicubic, bilinear = DisplayFilter::bilinear;
  for (const Camera& c :
       {Camera{"frames 4", 4, false, bilinear, 0, 28, 28}, Camera{"auto window", 1, true, bilinear, 0, 28, 28},
        Camera{"bicubic", 1, false, bicubic, 0, 28, 28}, Camera{"smooth 3", 1, false, bilinear, 3, 28, 28},
        Camera{"all, 37x13", 6, true, bicubic, 2.5, 37, 13}, Camera{"all, 1x1", 3, true, bicubic, 1, 1, 1},
        Camera{"all, 200x200", 2, true, bicubic, 0.7, 200, 200}}) {
    // The reference reads a plan's tier only through its noise draw (Fidelity::draw): the
    // tiers that share a draw share its run.
    BatchOutput r;
    std::optional<NoiseDraw> ref_draw;
    for (Tier tier : {Tier::standard, Tier::exact, Tier::fast}) {
      SCOPED_TRACE(std::string(c.name) + " " + tier_name(tier));
      const Plan plan = camera_plan(c, tier);
      if (ref_draw != plan.fidelity.draw) {
        ref->run(batch, plan, r);
        ref_draw = plan.fidelity.draw;
      }
      BatchOutput k;
      cl->run(batch, plan, k);
      const OutputDiff d = compare_outputs(k, r);
      test::expect_camera_parity(d.of(portalsim::Camera::mmw));
      EXPECT_LE(d.feature_max_abs, 1.0);
    }
  }
}

// The upper view's raw grid after the reference's stages up to `last`.
reference::Field raw_after(const ModelSettings& m, const Scenario& s, const std::string& last, uint64_t index = 0) {
  const reference::ViewScene vs = reference::view_scene(catalogue(), assets(), m, 0, s, index);
  reference::Field f;
  for (const std::string& stage : catalogue().sensors[0].chain_for(Model::physics)) {
    view_stage(stage).reference(vs, f);
    if (stage == last) break;
  }
  return f;
}

double variance(const std::vector<double>& v) {
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  double s = 0;
  for (double x : v) s += (x - mean) * (x - mean);
  return s / double(v.size() - 1);
}

// N frames, each with its own draw, averaged: the noise per raw pixel falls to NETD /
// sqrt(N). Two seeds on one scene differ by the noise alone (200x200 raw grid: 40,000
// cells, sampling error of a variance about 0.7%; tolerance 3%).
TEST(Camera, FramesAverageTheirNoise) {
  const Scenario s = test::random_scenario(catalogue(), 3, 2);
  for (int frames : {1, 4, 25}) {
    SCOPED_TRACE(frames);
    Plan p = physics_plan(1);
    p.model.frames = frames;
    p.model.raw_width = p.model.raw_height = 200;
    const reference::Field a = raw_after(p.model, s, "netd");
    p.model.seed = 2;
    const reference::Field b = raw_after(p.model, s, "netd");
    std::vector<double> d(a.v.size());
    for (size_t k = 0; k < d.size(); ++k) d[k] = a.v[k] - b.v[k];
    const double expected = 2 * p.model.netd * p.model.netd / frames;
    EXPECT_NEAR(variance(d) / expected, 1.0, 0.03);
  }
}

// The fast tier approximates N frames by one draw of NETD / sqrt(N) per raw pixel: the
// same distribution, other draws. Its images' noise (two seeds, a flat part of the scene)
// must have the standard tier's variance within 5%, and their noise the same share beyond
// two standard deviations within 1 point; and the draws must differ (it is an approximation).
TEST(Camera, FastTierFramesHaveTheSameDistribution) {
  const SceneBatch batch = test::batch_of(std::vector<Scenario>(64, Scenario{}));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto noise = [&](Tier tier) {
    Plan p = physics_plan(1);
    p.fidelity = tier_fidelity(tier);
    p.model.frames = 9;
    p.model.netd = 6;  // so that 9 frames leave 2 K, 25 gray levels a raw pixel
    p.features = false;
    BatchOutput a, b;
    cl->run(batch, p, a);
    p.model.seed = 2;
    cl->run(batch, p, b);
    std::vector<double> d;
    const std::vector<uint8_t>&pa = a.view("upper").pixels, &pb = b.view("upper").pixels;
    for (size_t k = 0; k < pa.size(); ++k)
      if (pa[k] > 0 && pa[k] < 255 && pb[k] > 0 && pb[k] < 255) d.push_back(double(pa[k]) - double(pb[k]));
    return std::pair(d, pa);
  };
  const auto [exact, exact_pixels] = noise(Tier::standard);
  const auto [fast, fast_pixels] = noise(Tier::fast);
  ASSERT_GT(exact.size(), 1000000u);
  ASSERT_GT(fast.size(), 1000000u);
  const double ve = variance(exact), vf = variance(fast);
  EXPECT_NEAR(vf / ve, 1.0, 0.05);
  const auto tail = [](const std::vector<double>& d, double v) {
    return double(std::count_if(d.begin(), d.end(), [&](double x) { return std::fabs(x) > 2 * std::sqrt(v); })) /
           double(d.size());
  };
  EXPECT_NEAR(tail(fast, vf), tail(exact, ve), 0.01);
  EXPECT_NE(exact_pixels, fast_pixels);
}

// The automatic window puts the raw grid's 1st and 99th percentiles (ranks round(q (n -
// 1))) on the fixed window's ends, linearly; a flat grid gets PS_WINDOW_MIN_SPAN.
TEST(Camera, AutoWindowPutsThePercentilesOnTheEnds) {
  const Scenario s = test::random_scenario(catalogue(), 5, 3);
  Plan p = physics_plan(3);
  p.model.window_auto = true;
  const reference::Field before = raw_after(p.model, s, "netd");
  const reference::Field after = raw_after(p.model, s, "window");
  std::vector<double> sorted = before.v;
  std::sort(sorted.begin(), sorted.end());
  const int n = int(sorted.size());
  const double lo = sorted[size_t(std::lround(0.01 * (n - 1)))], hi = sorted[size_t(std::lround(0.99 * (n - 1)))];
  for (size_t k = 0; k < before.v.size(); ++k)
    EXPECT_NEAR(after.v[k],
                p.model.window_lo + (before.v[k] - lo) / (hi - lo) * (p.model.window_hi - p.model.window_lo), 1e-9);
  p.model.netd = 0;
  p.model.raw_width = p.model.raw_height = 1;
  const reference::Field shown = raw_after(p.model, Scenario{}, "window");
  EXPECT_NEAR(shown.v[0], p.model.window_lo, 1e-9) << "a flat grid sits at the window's low end";
}

// Both filters reproduce a linear ramp across the raw grid (bilinear exactly, Keys' cubic
// too), the cubic one a quadratic away from the edges; smoothing is the Gaussian it names.
TEST(Camera, FiltersInterpolateAndSmoothingWidens) {
  const Plan p = physics_plan();
  const auto shown = [&](int raw, const std::function<double(int, int)>& value, DisplayFilter filter, double smooth) {
    ModelSettings m = p.model;
    m.display_filter = filter;
    m.smooth = smooth;
    m.window_lo = 0;
    m.window_hi = 255;  // one kelvin a gray level
    const reference::ViewScene v = reference::view_scene(catalogue(), assets(), m, 0, Scenario{}, 0);
    reference::Field f;
    f.width = f.height = raw;
    f.v.resize(size_t(raw) * raw);
    for (int r = 0; r < raw; ++r)
      for (int c = 0; c < raw; ++c) f.at(c, r) = value(c, r);
    reference::mmw_display(v, f);
    return f;
  };
  // Raw 20 over 200 pixels: pixel x sits at raw coordinate (x + 0.5) / 10 - 0.5.
  const auto u = [](int x) { return (x + 0.5) / 10 - 0.5; };
  for (DisplayFilter filter : {DisplayFilter::bilinear, DisplayFilter::bicubic}) {
    const reference::Field ramp = shown(
        20, [](int c, int r) { return 20 + 10.0 * c + 2.0 * r; }, filter, 0);
    for (int y = 20; y < 180; y += 7)
      for (int x = 20; x < 180; x += 5)
        EXPECT_NEAR(ramp.at(x, y), std::floor(20 + 10 * u(x) + 2 * u(y) + 0.5), 0) << x << " " << y;
  }
  const reference::Field quad = shown(
      20, [](int c, int) { return 10.0 + 0.6 * (c - 3) * (c - 3); }, DisplayFilter::bicubic, 0);
  for (int x = 30; x < 170; x += 3)
    EXPECT_EQ(quad.at(x, 100), std::floor(10 + 0.6 * (u(x) - 3) * (u(x) - 3) + 0.5)) << x;
  // Smoothing: a raw grid as fine as the view (the interpolation is then the grid itself)
  // holding one hot cell shows the Gaussian of sigma view pixels, normalised over +-4 sigma.
  const double sigma = 2.5, amplitude = 200.0;
  const reference::Field point = shown(
      200, [&](int c, int r) { return c == 100 && r == 100 ? amplitude : 0.0; }, DisplayFilter::bilinear, sigma);
  const int R = int(std::ceil(4 * sigma));
  double total = 0;
  for (int d = -R; d <= R; ++d) total += std::exp(-0.5 * d * d / (sigma * sigma));
  for (int dy = -R - 2; dy <= R + 2; ++dy)
    for (int dx = -R - 2; dx <= R + 2; ++dx) {
      const auto g = [&](int d) { return std::abs(d) > R ? 0.0 : std::exp(-0.5 * d * d / (sigma * sigma)) / total; };
      EXPECT_NEAR(point.at(100 + dx, 100 + dy), std::floor(amplitude * g(dx) * g(dy) + 0.5), 1e-9) << dx << " " << dy;
    }
}

// The defaults show the body: in both MMW views of the scenario (a gun at the right
// abdomen), the body stands above the room by at least 5 times the noise's standard
// deviation. Masks from the same scene without noise through a fixed window: below the
// midpoint of its levels room, above it body, each only where its whole 21 x 21
// neighbourhood agrees (the outline's blur left out). Signal: body mean less room mean of
// one seed's image; noise: the standard deviation of two seeds' difference over sqrt(2).
// tools/camera_snr.py measures the same from `portalsim simulate`.
TEST(Camera, DefaultsShowTheBody) {
  Plan plan;
  plan.model.model = Model::physics;
  Scenario gun;
  gun.objects[3] = static_cast<int16_t>(test::variant_of(catalogue(), "gun"));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const auto image = [&](const Plan& p) {
    BatchOutput o;
    cl->run(test::batch_of({gun}), p, o);
    return o;
  };
  Plan clean = plan, other = plan;
  clean.model.netd = 0;
  clean.model.window_auto = false;
  clean.model.window_lo = 285;
  clean.model.window_hi = 305;
  other.model.seed = plan.model.seed + 1;
  const BatchOutput c = image(clean), a = image(plan), b = image(other);
  for (const char* view : {"upper", "lower"}) {
    SCOPED_TRACE(view);
    const Sensor& s = catalogue().sensors[size_t(catalogue().sensor_index(view))];
    const int W = s.width, H = s.height;
    const std::vector<uint8_t>&pc = c.view(view).pixels, &pa = a.view(view).pixels, &pb = b.view(view).pixels;
    const auto [lo, hi] = std::minmax_element(pc.begin(), pc.end());
    const double mid = (double(*lo) + double(*hi)) / 2;
    double body = 0, room = 0, nb = 0, nr = 0;
    std::vector<double> d;
    for (int y = 10; y < H - 10; ++y)
      for (int x = 10; x < W - 10; ++x) {
        const bool above = pc[size_t(y) * W + x] > mid;
        bool agrees = true;
        for (int dy = -10; dy <= 10 && agrees; ++dy)
          for (int dx = -10; dx <= 10 && agrees; ++dx) agrees = (pc[size_t(y + dy) * W + x + dx] > mid) == above;
        if (!agrees) continue;
        const size_t k = size_t(y) * W + x;
        (above ? body : room) += pa[k];
        (above ? nb : nr) += 1;
        d.push_back(double(pa[k]) - double(pb[k]));
      }
    ASSERT_GT(nb, 1000);
    ASSERT_GT(nr, 1000);
    const double signal = body / nb - room / nr, noise = std::sqrt(variance(d) / 2);
    RecordProperty(std::string(view) + "_snr", std::to_string(signal / noise));
    EXPECT_GE(signal / noise, 5.0) << "body - room " << signal << " levels, noise " << noise;
  }
}

// The knobs: flags and spec keys from the registry, values checked with the file and field.
TEST(Camera, KnobsAreCheckedAndSet) {
  Plan p;
  set_knob(p, *find_knob("frames"), "10", "--frames");
  EXPECT_EQ(p.model.frames, 10);
  set_knob(p, *find_knob("window"), "auto", "--window");
  EXPECT_TRUE(p.model.window_auto);
  EXPECT_EQ(knob_text(find_knob("window")->get(p)), "auto");
  set_knob(p, *find_knob("window"), "288.5..301", "--window");
  EXPECT_FALSE(p.model.window_auto);
  EXPECT_EQ(p.model.window_lo, 288.5);
  EXPECT_EQ(p.model.window_hi, 301);
  EXPECT_EQ(knob_text(find_knob("window")->get(p)), "288.5..301");
  set_knob(p, *find_knob("display_filter"), "bicubic", "--display-filter");
  EXPECT_EQ(p.model.display_filter, DisplayFilter::bicubic);
  set_knob(p, *find_knob("smooth"), "1.5", "--smooth");
  EXPECT_EQ(p.model.smooth, 1.5);
  for (const auto& [key, bad] : std::vector<std::pair<std::string, std::string>>{{"frames", "0"},
                                                                                 {"frames", "2.5"},
                                                                                 {"frames", "1001"},
                                                                                 {"window", "300..290"},
                                                                                 {"window", "295"},
                                                                                 {"window", "autox"},
                                                                                 {"window", "nan..300"},
                                                                                 {"display_filter", "nearest"},
                                                                                 {"smooth", "-1"},
                                                                                 {"smooth", "inf"}}) {
    try {
      set_knob(p, *find_knob(key), bad, "spec.toml:4: " + key);
      ADD_FAILURE() << key << " = " << bad << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("spec.toml:4: " + key), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace portalsim
