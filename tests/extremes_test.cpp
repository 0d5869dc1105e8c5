// The model at its extremes: alpha 0 and 1, all-black and all-white images, every region
// holding the heaviest metal, no objects at all, block sizes from 1 to beyond the image,
// images of 1x1 and 4096x4096, sprites hanging off the image, huge noise, the largest
// seeds and scenario indices, batches of one and a million, and NaN, infinity and
// negative numbers wherever a user can type one.
//
// Unless a case is about rejection, every fidelity tier (exact, standard, fast) is held to
// its stated tolerance (plan/tolerance.h) against the fp64 reference, once with images
// materialised and once as a features-only run (the sparse path where the plan allows).
// Per-pixel noise in a features-only run is drawn by the fast tier's block-mean model,
// which does not draw the reference's pixels: there the fast tier's features are held
// statistically to their own model and, where pixels do not clip at 0 or 255, to the
// reference (expect_block_mean_noise). The physics model runs the same harness at NETD 0
// (ExtremePhysics and the cases that name it).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "assets/image_io.h"
#include "backend/compare.h"
#include "backend/reference/draws.h"
#include "backend/reference/stages.h"
#include "base/embedded.h"
#include "base/error.h"
#include "plan/plan.h"
#include "plan/tolerance.h"
#include "run_binary.h"
#include "support.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

constexpr std::array<Tier, 3> kTiers{Tier::exact, Tier::standard, Tier::fast};
constexpr uint64_t kMaxU64 = std::numeric_limits<uint64_t>::max();

// ---------------------------------------------------------------------------------------------
// Catalogue text edits.

std::string default_text() { return std::string(embedded::default_catalogue); }

// Rewrites the text line by line: `f` gets each line and returns its replacement, or nothing
// to keep it.
std::string edit_lines(const std::string& text,
                       const std::function<std::optional<std::string>(const std::string&)>& f) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    const std::optional<std::string> r = f(line);
    out += r ? *r : line;
    out += '\n';
  }
  return out;
}

std::vector<int> numbers_in(const std::string& line) {
  std::vector<int> v;
  const size_t open = line.find('['), close = line.find(']');
  if (open == std::string::npos || close == std::string::npos) return v;
  std::istringstream s(line.substr(open + 1, close - open - 1));
  std::string part;
  while (std::getline(s, part, ',')) v.push_back(std::stoi(part));
  return v;
}

std::string rect_text(const Rect& r) {
  return "[" + std::to_string(r.x) + ", " + std::to_string(r.y) + ", " + std::to_string(r.w) + ", " +
         std::to_string(r.h) + "]";
}

// Every region rectangle through `f(region id 1..13, is_mmw, rect)`: the built-in catalogue's
// `rects = { upper|lower = [...], ir = [...] }` lines.
std::string map_rects(const std::string& text, const std::function<Rect(int, bool, Rect)>& f) {
  int region = 0;
  return edit_lines(text, [&](const std::string& line) -> std::optional<std::string> {
    if (line.rfind("[[", 0) == 0) region = line == "[[regions]]" ? region + 1 : (region > 0 ? 100 : 0);
    if (region < 1 || region > kBuiltinRegions || line.rfind("rects = { ", 0) != 0) return std::nullopt;
    const size_t ir_at = line.find(", ir = [");
    const std::string mmw_view = line.substr(10, line.find(" = [") - 10);
    const std::vector<int> m = numbers_in(line), i = numbers_in(line.substr(ir_at));
    if (m.size() != 4 || i.size() != 4) return std::nullopt;
    return "rects = { " + mmw_view + " = " + rect_text(f(region, true, Rect{m[0], m[1], m[2], m[3]})) +
           ", ir = " + rect_text(f(region, false, Rect{i[0], i[1], i[2], i[3]})) + " }";
  });
}

// Every object's `size = [w, h]` through `f`.
std::string map_sizes(const std::string& text, const std::function<std::pair<int, int>(int, int)>& f) {
  bool object = false;
  return edit_lines(text, [&](const std::string& line) -> std::optional<std::string> {
    if (line.rfind("[", 0) == 0) object = line == "[[objects]]";
    if (!object || line.rfind("size = [", 0) != 0) return std::nullopt;
    const std::vector<int> v = numbers_in(line);
    if (v.size() != 2) return std::nullopt;
    const auto [w, h] = f(v[0], v[1]);
    return "size = [" + std::to_string(w) + ", " + std::to_string(h) + "]";
  });
}

// The built-in portal's view sizes: the two MMW views, then the IR view.
std::string set_view_sizes(const std::string& text, int mmw_w, int mmw_h, int ir_w, int ir_h) {
  std::string view;
  return edit_lines(text, [&](const std::string& line) -> std::optional<std::string> {
    if (line.rfind("[", 0) == 0) view = line == "[[views]]" ? "?" : "";
    if (!view.empty() && line.rfind("name = \"", 0) == 0) view = line.substr(8, line.find('"', 8) - 8);
    if (view.empty() || view == "?" || line.rfind("size = [", 0) != 0) return std::nullopt;
    const bool ir = view == "ir";
    return "size = [" + std::to_string(ir ? ir_w : mmw_w) + ", " + std::to_string(ir ? ir_h : mmw_h) + "]";
  });
}

// A subject's image files for the built-in portal's three views.
std::string subject_images(const std::string& upper, const std::string& lower, const std::string& ir) {
  return "images = { upper = \"" + upper + "\", lower = \"" + lower + "\", ir = \"" + ir + "\" }\n";
}

// Sets one [images] key (a line "key = value ...").
std::string set_image_key(const std::string& text, const std::string& key, const std::string& value) {
  bool done = false;
  std::string out = edit_lines(text, [&](const std::string& line) -> std::optional<std::string> {
    if (done || line.rfind(key + " = ", 0) != 0) return std::nullopt;
    done = true;
    return key + " = " + value;
  });
  if (!done) ADD_FAILURE() << "no \"" << key << " = \" line in the catalogue";
  return out;
}

// Inserts `lines` after the line `name = "<name>"` (a subject's or an object's table).
std::string add_after_name(const std::string& text, const std::string& name, const std::string& lines) {
  return replace_once(text, "name = \"" + name + "\"\n", "name = \"" + name + "\"\n" + lines);
}

// Keeps only the first [[subjects]] table.
std::string first_subject_only(const std::string& text) {
  const size_t first = text.find("[[subjects]]");
  const size_t second = text.find("[[subjects]]", first + 1);
  const size_t regions = text.find("# --- Regions");
  if (first == std::string::npos || second == std::string::npos || regions == std::string::npos || regions < second) {
    ADD_FAILURE() << "the default catalogue's subjects moved; update the test";
    return text;
  }
  return text.substr(0, second) + text.substr(regions);
}

// ---------------------------------------------------------------------------------------------
// Temporary folders and test images.

class TempDir {
 public:
  TempDir() { root_ = test::make_temp_dir("portalsim-extremes"); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  const fs::path& path() const { return root_; }
  std::string str() const { return root_.string(); }

 private:
  fs::path root_;
};

std::string write_gray(const fs::path& dir, const std::string& name, int w, int h, uint8_t value) {
  const fs::path p = dir / name;
  write_image(p.string(), Image(w, h, 1, value));
  return p.string();
}

// ---------------------------------------------------------------------------------------------
// A catalogue, its assets and both backends.

struct World {
  Catalogue cat;
  AssetSet assets;
  std::unique_ptr<Backend> ref, cl;
};

std::unique_ptr<World> make_world(const std::string& text, const std::string& dir = "") {
  auto w = std::make_unique<World>();
  w->cat = parse_catalogue(text, "test.toml", dir, "");
  w->assets = build_assets(w->cat);
  w->ref = make_reference_backend(w->cat, w->assets);
  w->cl = make_opencl_backend(w->cat, w->assets, test::runtime());
  return w;
}

// Reading `text` as test.toml is refused naming the file, `field` and `says`: the message
// ("" where it was accepted).
std::string expect_refused(const std::string& text, const std::string& field, const std::string& says) {
  try {
    parse_catalogue(text, "test.toml", "", "");
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("test.toml:"), std::string::npos) << what;
    EXPECT_NE(what.find(field + ": "), std::string::npos) << what;
    EXPECT_NE(what.find(says), std::string::npos) << what;
    return what;
  }
  ADD_FAILURE() << "accepted";
  return "";
}

World& default_world() {
  static std::unique_ptr<World> w = make_world(default_text());
  return *w;
}

// Every region holding an object: variants rotate from `first`.
Scenario crowded(const Catalogue& c, int subject, size_t first = 0) {
  Scenario s;
  s.subject = subject;
  for (int r = 0; r < c.region_count(); ++r) s.objects[r] = static_cast<int16_t>((first + r) % c.variant_list.size());
  return s;
}

Plan images_plan(const ModelSettings& m, Tier t) {
  Plan p;
  p.model = m;
  p.fidelity = tier_fidelity(t);
  return p;
}

Plan features_plan(const ModelSettings& m, Tier t) {
  Plan p = images_plan(m, t);
  p.images = 0;
  return p;
}

ModelSettings model(uint64_t seed, bool pattern, double sigma = 0, int block = 10, int metal_noise = 0) {
  ModelSettings m;
  m.seed = seed;
  m.pattern_noise = pattern;
  m.pixel_sigma = sigma;
  m.block = block;
  m.metal_noise = metal_noise;
  return m;
}

// The physics model at NETD 0 and IR NETD 0: the raw-grid path's noise is not the
// reference's draws and is held statistically in Physics.RawGridFeatureNoiseMatchesTheReference,
// and the fast tier's images draw their noise its own way, against which the exact tier's
// reference here is not held (Physics.FastTierDrawsMatchTheReference holds it). The window is
// 285..305 K, wide enough that flat white and black scenes stay unclipped: the raw-grid
// features path leaves each pixel's clamping out (the default 290..302 K clips them).
ModelSettings physics_model(uint64_t seed, int block = 10, int metal_noise = 0) {
  ModelSettings m = model(seed, false, 0.0, block, metal_noise);
  m.model = Model::physics;
  m.netd = 0;
  m.ir_netd = 0;
  m.window_lo = 285;
  m.window_hi = 305;
  return m;
}

std::string describe(const ModelSettings& m) {
  std::ostringstream s;
  s << (m.model == Model::physics ? "physics model, netd " + std::to_string(m.netd) + ", " : "") << "seed " << m.seed
    << ", pattern noise " << (m.pattern_noise ? "on" : "off") << ", pixel sigma " << m.pixel_sigma << ", block "
    << m.block << ", metal noise " << m.metal_noise;
  return s.str();
}

// The same shape as the reference: any difference here would make compare_outputs skip a part.
void expect_same_shape(const BatchOutput& a, const BatchOutput& ref) {
  EXPECT_EQ(a.n, ref.n);
  EXPECT_EQ(a.view("upper").width, ref.view("upper").width);
  EXPECT_EQ(a.view("upper").height, ref.view("upper").height);
  EXPECT_EQ(a.view("ir").width, ref.view("ir").width);
  EXPECT_EQ(a.view("ir").height, ref.view("ir").height);
  EXPECT_EQ(a.view("upper").pixels.size(), ref.view("upper").pixels.size());
  EXPECT_EQ(a.view("lower").pixels.size(), ref.view("lower").pixels.size());
  EXPECT_EQ(a.view("ir").pixels.size(), ref.view("ir").pixels.size());
  EXPECT_EQ(a.metal.size(), ref.metal.size());
  EXPECT_EQ(a.features.size(), ref.features.size());
  EXPECT_EQ(a.layout.block, ref.layout.block);
  EXPECT_EQ(a.layout.grids[0].blocks_x, ref.layout.grids[0].blocks_x);
  EXPECT_EQ(a.layout.grids[0].blocks_y, ref.layout.grids[0].blocks_y);
}

// Features are finite gray levels and metal zones lie in [1, 200]. (compare_outputs would let
// a NaN feature through: max() with NaN keeps the old value.)
void expect_in_range(const BatchOutput& o) {
  size_t bad = 0;
  float worst = 0;
  for (float f : o.features)
    if (!std::isfinite(f) || f < 0.0f || f > 255.0f) {
      if (bad++ == 0) worst = f;
    }
  EXPECT_EQ(bad, 0u) << "features outside [0, 255] or not finite, e.g. " << worst;
  size_t bad_metal = 0;
  for (uint8_t z : o.metal) bad_metal += z < 1 || z > 200;
  EXPECT_EQ(bad_metal, 0u) << "metal zones outside [1, 200]";
}

// How the fast tier's noisy features-only run is held: `statistical` against both its own
// model and the reference; `own_model` against its model only, where pixels clip at 0 or
// 255 and the block-mean model, which ignores that, does not describe the reference.
enum class FastNoisy { statistical, own_model };

// How many pixels each feature of `lay` averages: the blocks of each pooled view (the
// last row and column cut short by the view's edge), then the regions.
std::vector<double> feature_counts(const Catalogue& cat, const FeatureLayout& lay) {
  std::vector<double> c;
  for (int k : lay.pooled) {
    const Sensor& s = cat.sensors[k];
    for (int by = 0; by * lay.block < s.height; ++by)
      for (int bx = 0; bx * lay.block < s.width; ++bx)
        c.push_back(double(std::min(lay.block, s.width - bx * lay.block)) *
                    std::min(lay.block, s.height - by * lay.block));
  }
  for (int r = 0; r < cat.region_count(); ++r)  // in the first pooled view that sees it
    for (int k : lay.pooled)
      if (cat.sensors[k].sees(r)) {
        c.push_back(double(cat.sensors[k].rects[r].w) * cat.sensors[k].rects[r].h);
        break;
      }
  return c;
}

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// The thesis fast tier's features-only run with pixel noise (the block-mean model: each
// mean of c pixels gets one draw of N(0, sigma^2 / c), clamped to [0, 255]), in `o`, held
// to the tolerance table (Output::features_only_noisy). 1. Its own model: each feature's
// place in the clamped normal about the noise-free run's feature (randomised within the
// clamps' atoms), taken back to a standard normal, must be N(0, 1) in mean, sd and KS
// distance. 2. Where pixels do not clip, the reference: per value and on average within
// the noise-free bound plus the table's multiples of sigma sqrt(2 / c), the sd of the
// difference of two independent draws; and no bias.
void expect_block_mean_noise(World& w, const SceneBatch& batch, const ModelSettings& m, const BatchOutput& o,
                             const BatchOutput& ref, FastNoisy fast_noisy) {
  ModelSettings quiet_m = m;
  quiet_m.pixel_sigma = 0;
  BatchOutput quiet;
  w.cl->run(batch, features_plan(quiet_m, Tier::fast), quiet);
  ASSERT_EQ(quiet.features.size(), o.features.size());
  ASSERT_EQ(ref.features.size(), o.features.size());
  const std::vector<double> c = feature_counts(w.cat, o.layout);
  ASSERT_EQ(c.size(), size_t(o.layout.image_features()));
  std::vector<double> z;
  for (size_t k = 0; k < o.features.size(); ++k) {
    const double s = m.pixel_sigma / std::sqrt(c[k % c.size()]), mu = quiet.features[k], x = o.features[k];
    const double v = std::fmod((k + 1) * 0.6180339887498949, 1.0);  // spread over an atom
    double u;
    if (x <= 0)
      u = v * normal_cdf(-mu / s);
    else if (x >= 255)
      u = normal_cdf((255 - mu) / s) + v * (1 - normal_cdf((255 - mu) / s));
    else
      u = normal_cdf((x - mu) / s);
    z.push_back(reference::normal_quantile(std::clamp(u, 1e-300, 1 - 1e-16)));
  }
  // 0. The draws themselves, value by value where the feature is not clamped: the reference's
  // Box-Muller of the same Philox words (reference::block_mean_gaussian), within the
  // tolerance of plan/tolerance.h plus the two features' float rounding.
  size_t draws = 0, wrong = 0;
  double worst = 0;
  for (size_t k = 0; k < o.features.size(); ++k) {
    const double x = o.features[k], mu = quiet.features[k];
    if (x <= 0 || x >= 255) continue;
    const double s = m.pixel_sigma / std::sqrt(c[k % c.size()]);
    const double g = reference::block_mean_gaussian(m.seed, batch.first_index + k / c.size(), int(k % c.size()));
    const double ulps = 2 * (std::nextafter(float(std::max(x, mu)), 1e9f) - float(std::max(x, mu)));
    const double e = std::abs(x - mu - s * g);
    ++draws;
    if (e > s * (kBlockMeanDrawAbs + kBlockMeanDrawRel * std::abs(g)) + ulps) {
      if (wrong++ == 0) worst = e / s;
    }
  }
  EXPECT_GT(draws, 0u);
  EXPECT_EQ(wrong, 0u) << "block-mean draws off the reference's Box-Muller, the first by " << worst << " sd";
  const SampleComparison d = compare_samples(z);
  const double n = double(z.size());
  EXPECT_NEAR(d.mean_a, 0.0, 4 / std::sqrt(n)) << "block-mean draws: mean";
  EXPECT_NEAR(d.sd_a, 1.0, 4 / std::sqrt(2 * n)) << "block-mean draws: sd";
  EXPECT_LE(d.ks, d.ks_critical) << "block-mean draws: KS distance from N(0, 1)";
  if (fast_noisy != FastNoisy::statistical) return;
  const Bound& clean = tolerance_bound(m.model, Tier::fast, Output::features_only);
  const Bound& noisy = tolerance_bound(m.model, Tier::fast, Output::features_only_noisy);
  double sum_abs = 0, sum_signed = 0, sum_sd = 0;
  size_t over = 0;
  for (size_t k = 0; k < o.features.size(); ++k) {
    const double sd = m.pixel_sigma * std::sqrt(2 / c[k % c.size()]), e = double(o.features[k]) - ref.features[k];
    over += std::abs(e) > clean.max_abs + noisy.max_abs * sd;
    sum_abs += std::abs(e);
    sum_signed += e;
    sum_sd += sd;
  }
  EXPECT_EQ(over, 0u) << "features beyond " << noisy.max_abs << " sd of the reference";
  EXPECT_LE(sum_abs / n, clean.mean_abs + noisy.mean_abs * sum_sd / n) << "mean absolute feature error";
  EXPECT_NEAR(sum_signed / n, 0.0, 4 * sum_sd / n / std::sqrt(n) + clean.mean_abs) << "mean signed feature error";
}

struct Parity {
  BatchOutput ref_images, ref_features;
  std::array<BatchOutput, 3> images, features;  // in kTiers order
};

// The reference's features-only run renders the views with the stages of its images run and
// pools them (ReferenceBackend::run): its rows are the images run's. So it runs on the first
// scenarios only, held to the images run's rows to the bit, and the rest are taken from the
// images run (the reference's loops are most of these tests' time under the sanitizers).
constexpr size_t kReferenceFeaturesRun = 3;

BatchOutput reference_features(World& w, const SceneBatch& batch, const ModelSettings& m, const BatchOutput& images) {
  const Plan plan = features_plan(m, Tier::exact);
  SceneBatch head(batch.regions);
  head.first_index = batch.first_index;
  for (size_t i = 0; i < std::min(batch.size(), kReferenceFeaturesRun); ++i) head.push(batch.at(i));
  BatchOutput run;
  w.ref->run(head, plan, run);
  BatchOutput taken = images;
  for (size_t k = 0; k < taken.views.size(); ++k)
    if (!plan.image(static_cast<int>(k))) taken.views[k].pixels.clear();
  if (!plan.annotations) taken.annotations.clear();
  const size_t row = taken.layout.image_features(), zones = w.cat.zones;
  EXPECT_TRUE(std::equal(run.features.begin(), run.features.end(), taken.features.begin()))
      << "the reference's features-only rows are not its images run's";
  EXPECT_TRUE(std::equal(run.metal.begin(), run.metal.end(), taken.metal.begin()));
  EXPECT_EQ(run.features.size(), head.size() * row);
  EXPECT_EQ(run.metal.size(), plan.metal ? head.size() * zones : 0);
  for (size_t k = 0; k < taken.views.size(); ++k) EXPECT_EQ(run.views[k].pixels.empty(), taken.views[k].pixels.empty());
  return taken;
}

// Every tier against the reference, images plan and features-only plan.
std::unique_ptr<Parity> expect_parity(World& w, const SceneBatch& batch, const ModelSettings& m,
                                      const std::string& what, FastNoisy fast_noisy = FastNoisy::statistical) {
  SCOPED_TRACE(what + " (" + describe(m) + ", " + std::to_string(batch.size()) + " scenarios)");
  auto p = std::make_unique<Parity>();
  w.ref->run(batch, images_plan(m, Tier::exact), p->ref_images);
  p->ref_features = reference_features(w, batch, m, p->ref_images);
  expect_in_range(p->ref_images);
  expect_in_range(p->ref_features);
  for (size_t t = 0; t < kTiers.size(); ++t) {
    const Tier tier = kTiers[t];
    const Tolerance tol = model_tolerance(m.model, tier);
    SCOPED_TRACE(std::string("tier ") + tier_name(tier));
    {
      SCOPED_TRACE("images plan");
      BatchOutput& o = p->images[t];
      const Plan plan = images_plan(m, tier);
      w.cl->run(batch, plan, o);
      expect_same_shape(o, p->ref_images);
      expect_in_range(o);
      // The fast tier's Irwin-Hall pixel draws are held to the reference following them.
      BatchOutput ref_draws;
      const bool other_draws =
          plan.fidelity.draw != NoiseDraw::box_muller && m.model == Model::thesis && m.pixel_sigma > 0;
      if (other_draws) w.ref->run(batch, plan, ref_draws);
      EXPECT_EQ(check_tolerance(compare_outputs(o, other_draws ? ref_draws : p->ref_images), tol), "");
      EXPECT_EQ(o.metal, p->ref_images.metal);
    }
    {
      SCOPED_TRACE("features-only plan");
      BatchOutput& o = p->features[t];
      const Plan plan = features_plan(m, tier);
      w.cl->run(batch, plan, o);
      expect_same_shape(o, p->ref_features);
      expect_in_range(o);
      EXPECT_EQ(o.metal, p->ref_features.metal);
      if (tier == Tier::fast && m.model == Model::physics && m.netd > 0) {
        ADD_FAILURE() << "the raw-grid path's NETD draws are not the reference's: run the extremes at netd 0";
      } else if (tier == Tier::fast && m.pixel_sigma > 0 && m.model == Model::thesis) {
        // Block-mean noise model: other draws than the reference's pixels.
        EXPECT_EQ(plan.fidelity.noise, NoiseModel::block_mean);
        expect_block_mean_noise(w, batch, m, o, p->ref_features, fast_noisy);
      } else {
        EXPECT_EQ(check_tolerance(compare_outputs(o, p->ref_features), tol), "");
        // Sparse and dense pooling "give the same numbers to the bit" (plan.h), and the
        // features-only run draws the same noise as the images run: one row, two ways. (Not
        // held for the fast tier here: under -cl-fast-relaxed-math the final divisions of the
        // two paths differ in the last bit on ordinary scenes; the flat scenes of
        // ExtremeBlackWhite show where that leaves the pixel range.)
        const std::vector<float>& dense = p->images[t].features;
        if (tier != Tier::fast && o.features.size() == dense.size()) {
          size_t differ = 0, first = 0;
          for (size_t k = 0; k < dense.size(); ++k)
            if (o.features[k] != dense[k] && differ++ == 0) first = k;
          EXPECT_EQ(differ, 0u) << "features differ between the features-only run (" << test::features_path(*w.cl, plan)
                                << ") and the images run, e.g. #" << first << ": "
                                << (differ ? o.features[first] : 0.0f) << " against " << (differ ? dense[first] : 0.0f);
        }
      }
    }
  }
  return p;
}

// The first `n` scenarios of `b` (per-pixel noise is costly on the CPU device).
SceneBatch first_of(const SceneBatch& b, size_t n) {
  SceneBatch out(b.regions);
  out.first_index = b.first_index;
  for (size_t i = 0; i < std::min(n, b.size()); ++i) out.push(b.at(i));
  return out;
}

size_t count_differing(const uint8_t* a, const uint8_t* b, size_t n) {
  size_t d = 0;
  for (size_t i = 0; i < n; ++i) d += a[i] != b[i];
  return d;
}

// The features row of a subject with no objects: block and region means of its bases.
std::vector<double> base_features(const World& w, int subject, int block) {
  const FeatureLayout f = FeatureLayout::of(w.cat, block);
  const int W = w.cat.sensors[0].width, H = w.cat.sensors[0].height;
  std::vector<double> row;
  for (int view = 0; view < 2; ++view) {
    const Image& img = w.assets.bases[subject][view];
    for (int by = 0; by < f.grids[0].blocks_y; ++by)
      for (int bx = 0; bx < f.grids[0].blocks_x; ++bx) {
        double sum = 0;
        int count = 0;
        for (int y = by * block; y < std::min(H, (by + 1) * block); ++y)
          for (int x = bx * block; x < std::min(W, (bx + 1) * block); ++x, ++count) sum += img.at(x, y);
        row.push_back(sum / count);
      }
  }
  for (int k = 0; k < kBuiltinRegions; ++k) {
    const Image& img = w.assets.bases[subject][test::mmw_view_of(w.cat, k)];
    const Rect& r = test::mmw_rect(w.cat, k);
    double sum = 0;
    for (int y = r.y; y < r.y + r.h; ++y)
      for (int x = r.x; x < r.x + r.w; ++x) sum += img.at(x, y);
    row.push_back(sum / (double(r.w) * r.h));
  }
  return row;
}

// Each scenario's images equal its subject's bases, in the images plan's output `o`.
void expect_images_are_bases(const World& w, const SceneBatch& batch, const BatchOutput& o, const std::string& who) {
  const size_t mmw = size_t(o.view("upper").width) * o.view("upper").height,
               ir = size_t(o.view("ir").width) * o.view("ir").height;
  ASSERT_EQ(o.view("upper").pixels.size(), batch.size() * mmw) << who;
  ASSERT_EQ(o.view("ir").pixels.size(), batch.size() * ir) << who;
  size_t upper = 0, lower = 0, irs = 0;
  for (size_t i = 0; i < batch.size(); ++i) {
    const auto& b = w.assets.bases[batch.subject[i]];
    upper += count_differing(o.view("upper").of(i), b[0].pixels.data(), mmw);
    lower += count_differing(o.view("lower").of(i), b[1].pixels.data(), mmw);
    irs += count_differing(o.view("ir").of(i), b[2].pixels.data(), ir);
  }
  EXPECT_EQ(upper, 0u) << who << ": upper pixels differing from the base";
  EXPECT_EQ(lower, 0u) << who << ": lower pixels differing from the base";
  EXPECT_EQ(irs, 0u) << who << ": IR pixels differing from the base";
}

// Each scenario's features equal its subject's base means (within `tol`).
void expect_features_are_base_means(const World& w, const SceneBatch& batch, const BatchOutput& o, int block,
                                    double tol, const std::string& who) {
  const size_t F = o.layout.image_features();
  ASSERT_EQ(o.features.size(), batch.size() * F) << who;
  double worst = 0;
  size_t worst_at = 0;
  std::vector<std::vector<double>> rows(w.cat.subjects.size());
  for (size_t i = 0; i < batch.size(); ++i) {
    std::vector<double>& expect = rows[batch.subject[i]];
    if (expect.empty()) expect = base_features(w, batch.subject[i], block);
    ASSERT_EQ(expect.size(), F);
    for (size_t k = 0; k < F; ++k) {
      const double e = std::abs(double(o.features_of(i)[k]) - expect[k]);
      if (!(e <= worst)) worst = e, worst_at = k;
    }
  }
  EXPECT_LE(worst, tol) << who << ": feature " << worst_at << " is off the base mean by " << worst;
}

// `sprite` centred on `rect` as the reference places it: where its coverage is 255 the image
// must show the sprite's value, where it is 0 the base's. Counts the pixels checked and wrong.
struct OpaqueCheck {
  size_t checked = 0, wrong = 0, clear_checked = 0, clear_wrong = 0;
};
void check_opaque(const Image& sprite, const Rect& rect, const uint8_t* img, const Image& base, OpaqueCheck& c) {
  const int W = base.width, H = base.height;
  const int x0 = rect.x + static_cast<int>(std::floor((rect.w - sprite.width) / 2.0));
  const int y0 = rect.y + static_cast<int>(std::floor((rect.h - sprite.height) / 2.0));
  for (int sy = 0; sy < sprite.height; ++sy)
    for (int sx = 0; sx < sprite.width; ++sx) {
      const int x = x0 + sx, y = y0 + sy;
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      const uint8_t got = img[size_t(y) * W + x];
      if (sprite.at(sx, sy, 1) == 255) {
        ++c.checked;
        c.wrong += got != sprite.at(sx, sy, 0);
      } else if (sprite.at(sx, sy, 1) == 0) {
        ++c.clear_checked;
        c.clear_wrong += got != base.at(x, y);
      }
    }
}

// ---------------------------------------------------------------------------------------------
// Running the binary (as tests/cli_test.cpp does).

struct Rejection {
  std::vector<std::string> args;  // without --out
  std::vector<std::string> needles;
};

// Runs every command at once (each with its own absent --out folder); each must fail cleanly:
// non-zero exit, no signal, stderr naming every needle, nothing on stdout, no output folder.
void expect_all_rejected(const std::vector<Rejection>& cases) {
  TempDir t;
  fs::create_directory(t.path() / "cap");
  std::vector<Running> running;
  std::vector<fs::path> outs;
  for (size_t i = 0; i < cases.size(); ++i) {
    outs.push_back(t.path() / ("out" + std::to_string(i)));
    std::vector<std::string> args = cases[i].args;
    args.push_back("--out");
    args.push_back(outs.back().string());
    running.push_back(start(t.path() / "cap", args));
  }
  for (size_t i = 0; i < cases.size(); ++i) {
    const Result r = finish(running[i], 60);  // this suite's runs are short
    SCOPED_TRACE(describe(r));
    EXPECT_FALSE(r.timed_out);
    EXPECT_FALSE(r.signaled) << "killed by signal " << r.signal;
    EXPECT_TRUE(r.exited && r.status != 0) << "a command with a bad number must be rejected";
    for (const std::string& n : cases[i].needles) EXPECT_TRUE(has(r.err, n)) << "stderr does not name \"" << n << "\"";
    EXPECT_EQ(r.out, "") << "nothing should be printed on stdout";
    std::error_code ec;
    EXPECT_FALSE(fs::exists(outs[i], ec)) << outs[i] << " must not be left behind";
  }
}

// =============================================================================================
// 1. Alpha 0 and 1.

TEST(ExtremeAlpha, ZeroMakesObjectsInvisible) {
  const std::string text = replace_once(default_text(), "alpha = 0.9", "alpha = 0.0");
  auto w = make_world(text);
  ASSERT_EQ(w->cat.images.alpha, 0.0);
  const SceneBatch batch = test::batch_of(coverage(w->cat, 240, 13), 5);
  {
    // No pattern noise: nothing but the objects could change a pixel, and they are invisible.
    const auto p = expect_parity(*w, batch, model(11, false), "alpha 0");
    expect_images_are_bases(*w, batch, p->ref_images, "reference");
    for (size_t t = 0; t < kTiers.size(); ++t) {
      expect_images_are_bases(*w, batch, p->images[t], tier_name(kTiers[t]));
      expect_features_are_base_means(*w, batch, p->features[t], 10, 1e-3,
                                     std::string(tier_name(kTiers[t])) + " features-only");
    }
  }
  // The pattern noise is still laid over the (invisible) objects.
  expect_parity(*w, batch, model(12, true), "alpha 0 with pattern noise");
}

TEST(ExtremeAlpha, OneMakesSpritesOpaque) {
  const std::string text = replace_once(default_text(), "alpha = 0.9", "alpha = 1");
  auto w = make_world(text);
  ASSERT_EQ(w->cat.images.alpha, 1.0);
  const std::vector<Scenario> singles = coverage(w->cat, 0, 13);  // one object per scenario
  const SceneBatch batch = test::batch_of(singles, 0);
  const auto p = expect_parity(*w, batch, model(21, false), "alpha 1, one object");
  auto check = [&](const BatchOutput& o, const std::string& who) {
    OpaqueCheck mmw, ir;
    for (size_t i = 0; i < singles.size(); ++i) {
      const Scenario& s = singles[i];
      for (int r = 0; r < kBuiltinRegions; ++r) {
        const int v = s.objects[r];
        if (v < 0) continue;
        const int view = test::mmw_view_of(w->cat, r);
        const Sensor &mv = w->cat.sensors[view], &iv = w->cat.sensors[2];
        check_opaque(w->assets.sprite(mv, v), mv.rects[r], o.view(mv.name).of(i), w->assets.bases[s.subject][view],
                     mmw);
        check_opaque(w->assets.sprite(iv, v), iv.rects[r], o.view("ir").of(i), w->assets.bases[s.subject][2], ir);
      }
    }
    EXPECT_GT(mmw.checked, 10000u) << who;
    EXPECT_EQ(mmw.wrong, 0u) << who << ": MMW pixels under full coverage that are not the sprite's, of " << mmw.checked;
    EXPECT_EQ(mmw.clear_wrong, 0u) << who << ": MMW pixels under zero coverage that are not the base's";
    EXPECT_GT(ir.checked, 1000u) << who;
    EXPECT_EQ(ir.wrong, 0u) << who << ": IR pixels under full coverage that are not the sprite's, of " << ir.checked;
    EXPECT_EQ(ir.clear_wrong, 0u) << who << ": IR pixels under zero coverage that are not the base's";
  };
  check(p->ref_images, "reference");
  for (size_t t = 0; t < kTiers.size(); ++t) check(p->images[t], tier_name(kTiers[t]));
  // Crowds, with both kinds of noise.
  const SceneBatch crowds = test::batch_of(coverage(w->cat, 120, 13, false), 77);
  expect_parity(*w, crowds, model(22, true), "alpha 1, crowds");
  expect_parity(*w, first_of(crowds, 25), model(23, true, 4.0), "alpha 1, crowds, pixel noise");
}

// At the default alpha of 0.9 about one opaque pixel in ten blends to an exact x.5 tie
// (0.9 s + 0.1 v); the fp64 kernels must resolve it as the fp64 reference does, which needs
// the catalogue's alpha itself, not its nearest float. Alpha 0.5 (exact in float) is the
// control.
TEST(ExtremeAlpha, ExactTierKeepsTheCataloguesAlpha) {
  for (const char* alpha : {"0.5", "0.9"}) {
    SCOPED_TRACE(std::string("alpha = ") + alpha);
    auto w = make_world(replace_once(default_text(), "alpha = 0.9", std::string("alpha = ") + alpha));
    const SceneBatch batch = test::batch_of(coverage(w->cat, 0, 13), 0);
    BatchOutput ref, exact;
    w->ref->run(batch, images_plan(model(5, false), Tier::exact), ref);
    w->cl->run(batch, images_plan(model(5, false), Tier::exact), exact);
    const OutputDiff d = compare_outputs(exact, ref);
    EXPECT_EQ(check_tolerance(d, tier_tolerance(Tier::exact)), "")
        << "MMW pixels differing: " << d.of(Camera::mmw).share_differing * d.of(Camera::mmw).pixels << " of "
        << d.of(Camera::mmw).pixels;
  }
}

// =============================================================================================
// 2. All-black and all-white bases and sprites (user image files). Sprite files are used at
// their own size (40x30 MMW, 20x15 IR here; the assets do not resample them to `size`).
// At alpha 0.9, white over black blends to 229.5 and black over white to 25.5: every covered
// pixel is an exact x.5 tie, which the fp64 kernels must round as the reference does.

void black_and_white(uint8_t base, uint8_t sprite) {
  TempDir t;
  const std::string b = std::to_string(base), s = std::to_string(sprite);
  const std::string up = write_gray(t.path(), "base-" + b + ".png", 200, 200, base);
  const std::string ir = write_gray(t.path(), "base-ir-" + b + ".png", 100, 200, base);
  const std::string sh = write_gray(t.path(), "sprite-h-" + s + ".png", 40, 30, sprite);
  const std::string sv = write_gray(t.path(), "sprite-v-" + s + ".png", 30, 40, sprite);
  const std::string ih = write_gray(t.path(), "sprite-ir-h-" + s + ".png", 20, 15, sprite);
  const std::string iv = write_gray(t.path(), "sprite-ir-v-" + s + ".png", 15, 20, sprite);
  std::string text = default_text();
  for (int k = 1; k <= 5; ++k) text = add_after_name(text, "subject-" + std::to_string(k), subject_images(up, up, ir));
  for (const Object& o : test::catalogue().objects)  // every object's drawings are files
    text = add_after_name(text, o.name,
                          o.variants.size() == 2 ? "mmw_h = \"" + sh + "\"\nmmw_v = \"" + sv + "\"\nir_h = \"" + ih +
                                                       "\"\nir_v = \"" + iv + "\"\n"
                                                 : "mmw = \"" + sh + "\"\nir = \"" + ih + "\"\n");
  auto w = make_world(text, t.str());
  for (const auto& views : w->assets.bases)
    for (const Image& img : views)
      ASSERT_TRUE(std::all_of(img.pixels.begin(), img.pixels.end(), [&](uint8_t v) { return v == base; }));
  for (const Image& sp : w->assets.sprites[w->cat.sensors[0].sprite_set]) ASSERT_EQ(sp.at(0, 0, 0), sprite);

  std::vector<Scenario> scenes;
  for (int subject = 0; subject < 5; ++subject) scenes.push_back(crowded(w->cat, subject, subject));
  for (const Scenario& s : test::parity_set(w->cat, 200, 13)) scenes.push_back(s);
  const SceneBatch batch = test::batch_of(scenes, 1000);

  // Pattern noise pushes past both ends: the kernels must clamp as the reference does.
  expect_parity(*w, batch, model(31, true, 0.0, 10, 3), "pattern noise");
  // The physics model's window over flat black and white bodies.
  expect_parity(*w, first_of(batch, 60), physics_model(34, 10, 3), "physics model");
  {
    // Neither noise: every pixel is the base or the blend of base and sprite.
    const auto p = expect_parity(*w, batch, model(32, false), "no noise");
    if (base == sprite) {
      for (size_t t = 0; t < kTiers.size(); ++t) {
        const BatchOutput& o = p->images[t];
        for (const std::vector<uint8_t>* v : {&o.view("upper").pixels, &o.view("lower").pixels, &o.view("ir").pixels})
          EXPECT_TRUE(std::all_of(v->begin(), v->end(), [&](uint8_t x) { return x == base; }))
              << tier_name(kTiers[t]) << ": a flat scene must stay flat";
        // Every mean of a flat scene is its gray level, exactly.
        for (const BatchOutput* f : {&p->images[t], &p->features[t]}) {
          const size_t off =
              std::count_if(f->features.begin(), f->features.end(), [&](float x) { return x != float(base); });
          EXPECT_EQ(off, 0u) << tier_name(kTiers[t]) << (f == &o ? " images plan" : " features-only plan")
                             << ": means of a flat scene that are not exactly " << int(base) << ", of "
                             << f->features.size();
        }
      }
    }
  }
  {
    // Per-pixel noise of sigma 8 (at most 5.8 sigma from the 24-bit Box-Muller): black stays
    // within [0, 47], white within [208, 255] where no sprite of the other colour lies, and
    // nothing wraps around. The block-mean model ignores clipping, so the fast tier's
    // features-only run is held to its own model only.
    const auto p = expect_parity(*w, first_of(batch, 25), model(33, false, 8.0), "pixel noise", FastNoisy::own_model);
    if (base == sprite) {
      for (size_t t = 0; t < kTiers.size(); ++t) {
        const BatchOutput& o = p->images[t];
        for (const std::vector<uint8_t>* v : {&o.view("upper").pixels, &o.view("lower").pixels, &o.view("ir").pixels}) {
          const auto [lo, hi] = std::minmax_element(v->begin(), v->end());
          if (base == 0)
            EXPECT_LE(*hi, 47) << tier_name(kTiers[t]) << ": black image with sigma 8";
          else
            EXPECT_GE(*lo, 208) << tier_name(kTiers[t]) << ": white image with sigma 8 (a wrap past 255?)";
          EXPECT_GT(*hi, *lo) << "the noise did something";
        }
      }
    }
  }
}

TEST(ExtremeBlackWhite, BlackBaseWhiteSprites) { black_and_white(0, 255); }
TEST(ExtremeBlackWhite, WhiteBaseBlackSprites) { black_and_white(255, 0); }
TEST(ExtremeBlackWhite, AllBlack) { black_and_white(0, 0); }
TEST(ExtremeBlackWhite, AllWhite) { black_and_white(255, 255); }

// =============================================================================================
// 3. The heaviest metal in every region: zones clamp at 1.

TEST(ExtremeMetal, HeaviestMetalInEveryRegionClampsAtOne) {
  World& w = default_world();
  const int gun = w.cat.find_object("gun");
  ASSERT_GE(gun, 0);
  ASSERT_EQ(w.cat.metal_categories[w.cat.objects[gun].metal], "heavy");
  const int first = w.cat.objects[gun].first_variant;
  std::vector<Scenario> scenes;
  for (int s = 0; s < static_cast<int>(w.cat.subjects.size()); ++s)
    for (int mix = 0; mix < 2; ++mix) {
      Scenario sc;
      sc.subject = s;
      for (int r = 0; r < kBuiltinRegions; ++r) sc.objects[r] = static_cast<int16_t>(first + (mix ? r % 2 : 0));
      scenes.push_back(sc);
    }
  // Influence sums per zone (the same for every scenario: all 13 regions hold heavy metal).
  std::array<int, kBuiltinZones> sum{};
  for (int r = 0; r < kBuiltinRegions; ++r)
    for (int z = 0; z < kBuiltinZones; ++z) sum[z] += w.cat.influence[w.cat.objects[gun].metal][r][z];
  int clamped = 0;
  for (int z = 0; z < kBuiltinZones; ++z) clamped += sum[z] >= 200 + 199;
  ASSERT_GT(clamped, 5) << "the test needs zones far below 1";

  struct Case {
    uint64_t seed, first;
    int noise;
  };
  for (const Case c : {Case{0, 0, 0}, Case{0, 0, 199}, Case{kMaxU64, 0, 199}, Case{kMaxU64, kMaxU64 - 9, 199},
                       Case{0, kMaxU64 - 9, 199}}) {
    const SceneBatch batch = test::batch_of(scenes, c.first);
    const ModelSettings m = model(c.seed, true, 0.0, 10, c.noise);
    const auto p = expect_parity(w, batch, m, "gun in all 13 regions");
    SCOPED_TRACE(describe(m) + ", first index " + std::to_string(c.first));
    for (size_t t = 0; t < kTiers.size(); ++t) {
      EXPECT_EQ(p->images[t].metal, p->ref_images.metal) << tier_name(kTiers[t]);
      EXPECT_EQ(p->features[t].metal, p->ref_images.metal) << tier_name(kTiers[t]);
    }
    const BatchOutput& o = p->ref_images;
    ASSERT_EQ(o.metal.size(), scenes.size() * kBuiltinZones);
    for (size_t i = 0; i < scenes.size(); ++i) {
      const auto& base = w.cat.subjects[scenes[i].subject].base_zones;
      for (int z = 0; z < kBuiltinZones; ++z) {
        const int got = o.metal_of(i)[z], exact = base[z] - sum[z];
        EXPECT_GE(got, 1) << "zone " << z + 1;
        EXPECT_LE(got, 200) << "zone " << z + 1;
        if (c.noise == 0)
          EXPECT_EQ(got, std::clamp(exact, 1, 200)) << "zone " << z + 1;
        else if (sum[z] == 0)
          EXPECT_EQ(got, base[z]) << "zone " << z + 1 << ": no influence, no noise";
        else if (exact + c.noise < 1)
          EXPECT_EQ(got, 1) << "zone " << z + 1 << ": base - influence = " << exact;
        else
          EXPECT_LE(std::abs(got - std::clamp(exact, 1, 200)), c.noise) << "zone " << z + 1;
      }
    }
  }
}

// =============================================================================================
// 4. No objects: the subject's base images, base means and base zones.

TEST(ExtremeEmpty, NoObjectsGiveTheBase) {
  World& w = default_world();
  std::vector<Scenario> scenes;
  for (int k = 0; k < 3; ++k)
    for (int s = 0; s < static_cast<int>(w.cat.subjects.size()); ++s) {
      Scenario sc;
      sc.subject = s;
      scenes.push_back(sc);
    }
  for (const auto& [seed, first, block] :
       {std::tuple{uint64_t{0}, uint64_t{0}, 10}, std::tuple{kMaxU64, kMaxU64 - 14, 7}}) {
    const SceneBatch batch = test::batch_of(scenes, first);
    const ModelSettings m = model(seed, true, 0.0, block, 50);
    const auto p = expect_parity(w, batch, m, "no objects");
    SCOPED_TRACE(describe(m));
    expect_images_are_bases(w, batch, p->ref_images, "reference");
    expect_features_are_base_means(w, batch, p->ref_features, block, 1e-4, "reference");
    for (size_t t = 0; t < kTiers.size(); ++t) {
      const std::string who = tier_name(kTiers[t]);
      expect_images_are_bases(w, batch, p->images[t], who);
      expect_features_are_base_means(w, batch, p->images[t], block, 1e-4, who + " images plan");
      expect_features_are_base_means(w, batch, p->features[t], block, 1e-4, who + " features-only");
      for (const BatchOutput* o : {&p->images[t], &p->features[t]}) {
        ASSERT_EQ(o->metal.size(), scenes.size() * kBuiltinZones);
        for (size_t i = 0; i < scenes.size(); ++i) {
          const auto& base = w.cat.subjects[scenes[i].subject].base_zones;
          EXPECT_TRUE(std::equal(base.begin(), base.end(), o->metal_of(i))) << who << " scenario " << i;
        }
      }
    }
  }
}

// =============================================================================================
// 5. Block sizes 1, 7, the image, and beyond it.

TEST(ExtremeBlock, SizesFromOnePixelToBeyondTheImage) {
  World& w = default_world();
  for (int block : {1, 7, 200, 256, 257, 500, 65536}) {
    SCOPED_TRACE("block " + std::to_string(block));
    const FeatureLayout lay = FeatureLayout::of(w.cat, block);
    EXPECT_EQ(lay.grids[0].blocks_x, (200 + block - 1) / block);
    EXPECT_EQ(lay.grids[0].blocks_y, (200 + block - 1) / block);
    EXPECT_EQ(lay.image_features(), 2 * lay.grids[0].blocks_x * lay.grids[0].blocks_y + kBuiltinRegions);
    EXPECT_EQ(lay.names().size(), static_cast<size_t>(lay.row_features()));
    Plan check = features_plan(model(0, true, 0.0, block), Tier::standard);
    EXPECT_NO_THROW(validate(check, w.cat));
    const SceneBatch batch = test::batch_of(coverage(w.cat, block == 1 ? 40 : 120, 13, false), 300);
    const auto p = expect_parity(w, batch, model(41, true, 0.0, block), "block");
    if (block >= 200) {
      // One block per view: its mean is the whole view's, in every output with images.
      EXPECT_EQ(lay.grids[0].blocks_x, 1);
      EXPECT_EQ(lay.grids[0].blocks_y, 1);
      for (const BatchOutput* o : {&p->ref_images, &p->images[0], &p->images[1], &p->images[2]}) {
        ASSERT_EQ(o->features.size(), batch.size() * (2 + kBuiltinRegions));
        for (size_t i = 0; i < batch.size(); ++i) {
          const size_t px = size_t(o->view("upper").width) * o->view("upper").height;
          double up = 0, lo = 0;
          for (size_t q = 0; q < px; ++q) up += o->view("upper").of(i)[q], lo += o->view("lower").of(i)[q];
          EXPECT_NEAR(o->features_of(i)[0], up / px, 1e-3) << "scenario " << i;
          EXPECT_NEAR(o->features_of(i)[1], lo / px, 1e-3) << "scenario " << i;
        }
      }
    }
  }
  // Per-pixel noise (the dense path everywhere but the fast tier's block-mean model).
  for (int block : {7, 500}) {
    const SceneBatch batch = test::batch_of(coverage(w.cat, 20, 6, false), 900);
    expect_parity(w, batch, model(42, true, 5.0, block), "block with pixel noise");
  }
  Plan too_big = features_plan(model(0, true, 0.0, 65537), Tier::standard);
  EXPECT_THROW(validate(too_big, w.cat), InputError);
}

// =============================================================================================
// 6. Images of 1x1 and 4096x4096.

TEST(ExtremeImageSize, OneByOne) {
  std::string text = default_text();
  text = set_view_sizes(text, 1, 1, 1, 1);
  text = map_rects(text, [](int, bool, Rect) { return Rect{0, 0, 1, 1}; });
  for (const std::string noise : {"40", "1"}) {
    SCOPED_TRACE("noise_size " + noise);
    auto w = make_world(set_image_key(text, "noise_size", noise));
    ASSERT_EQ(w->cat.sensors[0].width, 1);
    ASSERT_EQ(w->cat.sensors[2].rects[12].w, 1);
    const SceneBatch batch = test::batch_of(coverage(w->cat, 300, 13), 42);
    for (int block : {1, 10}) expect_parity(*w, batch, model(61, true, 0.0, block), "1x1 images");
    expect_parity(*w, batch, model(62, true, 3.0, 1), "1x1 images with pixel noise", FastNoisy::own_model);
    const FeatureLayout lay = FeatureLayout::of(w->cat, 10);
    EXPECT_EQ(lay.image_features(), 2 + kBuiltinRegions);
  }
}

// Views of 37x23 pixels (851, odd and not a multiple of 16), noisy in `tier`, whose draw is
// `draw`: the fused kernel equals the chain of stage kernels to the bit, and the reference
// following the draws within the tier's bounds.
void odd_views_render_as_the_stages(Tier tier, NoiseDraw draw) {
  std::string text = default_text();
  text = set_view_sizes(text, 37, 23, 37, 23);
  text = map_rects(text, [](int, bool, Rect) { return Rect{0, 0, 37, 23}; });
  auto w = make_world(text);
  const SceneBatch batch = test::batch_of(coverage(w->cat, 40, 4), 7);
  Plan plan = images_plan(model(63, true, 3.0, 1), tier);
  ASSERT_EQ(plan.fidelity.draw, draw);
  BatchOutput fused, staged, ref;
  w->cl->run(batch, plan, fused);
  w->ref->run(batch, plan, ref);
  EXPECT_EQ(check_tolerance(compare_outputs(fused, ref), model_tolerance(Model::thesis, tier)), "");
  plan.fidelity.fused = false;
  w->cl->run(batch, plan, staged);
  for (size_t k = 0; k < fused.views.size(); ++k) {
    ASSERT_EQ(fused.views[k].pixels.size(), batch.size() * 37 * 23) << fused.views[k].name;
    EXPECT_EQ(fused.views[k].pixels, staged.views[k].pixels) << fused.views[k].name;
  }
}

// The fast tier's Irwin-Hall vector path ends on a run of 16 that overlaps the one before
// it, its draws taken pixel by pixel.
TEST(ExtremeImageSize, OddViewsEndTheFastTiersNoisyRunsAlike) {
  odd_views_render_as_the_stages(Tier::fast, NoiseDraw::irwin_hall);
}

// The standard tier's Box-Muller noise takes the fused kernel's row path, where an odd width
// makes rows start mid-pair; the noise stage finds each pixel's pair on its own.
TEST(ExtremeImageSize, OddViewsPairTheBoxMullerNoiseAsTheStages) {
  odd_views_render_as_the_stages(Tier::standard, NoiseDraw::box_muller);
}

// A 4096x4096 catalogue: the default's rectangles and noise tile scaled by 20 (IR 2048x4096;
// the objects' drawings follow the views' scale, 20.48 pixels per field unit), one subject to
// keep the procedural images quick.
World& world_4096() {
  static std::unique_ptr<World> w = [] {
    std::string text = first_subject_only(default_text());
    text = set_view_sizes(text, 4096, 4096, 2048, 4096);
    text = set_image_key(text, "noise_size", "800");
    text = map_rects(text, [](int, bool, Rect r) { return Rect{r.x * 20, r.y * 20, r.w * 20, r.h * 20}; });
    return make_world(text);
  }();
  return *w;
}

std::vector<Scenario> three_scenes_4096(const Catalogue& c) {
  std::vector<Scenario> v(3);
  for (int r : {0, 4, 8, 12}) v[1].objects[r] = static_cast<int16_t>((r * 3) % c.variant_list.size());
  v[2] = crowded(c, 0, 5);
  return v;
}

TEST(ExtremeImageSize, FourThousandNinetySix) {
  World& w = world_4096();
  ASSERT_EQ(w.cat.sensors[0].width, 4096);
  ASSERT_EQ(w.assets.bases[0][0].width, 4096);
  ASSERT_EQ(w.assets.bases[0][2].width, 2048);
  const SceneBatch batch = test::batch_of(three_scenes_4096(w.cat), 7);
  expect_parity(w, batch, model(71, true, 0.0, 512), "4096x4096");
}

// =============================================================================================
// 7. Sprites partly outside the image. A sprite is centred on its region, which must lie in
// the view, so its centre pixel always stays inside: 400x400 sprites on 1x1 regions at the
// corners leave three quarters of each sprite (and of its noise tile) outside.

TEST(ExtremeSprites, PartlyOutsideTheImage) {
  // One subject keeps the sparse path's per-(variant, region, subject, pattern) tables, each
  // a whole view here, quick to build.
  const std::string big = map_sizes(first_subject_only(default_text()), [](int, int) { return std::pair{400, 400}; });
  // Regions at the corners of both views.
  const std::string corners = map_rects(big, [](int region, bool mmw, Rect) {
    switch (region % 4) {
      case 0:
        return mmw ? Rect{0, 0, 1, 1} : Rect{0, 0, 1, 1};
      case 1:
        return mmw ? Rect{199, 199, 1, 1} : Rect{99, 199, 1, 1};
      case 2:
        return mmw ? Rect{199, 0, 1, 1} : Rect{99, 0, 1, 1};
      default:
        return mmw ? Rect{0, 199, 1, 1} : Rect{0, 199, 1, 1};
    }
  });
  for (const auto& [name, text] :
       {std::pair{"400x400 sprites at the corners", corners},
        std::pair{"400x400 sprites, 600x600 noise tile, default regions", set_image_key(big, "noise_size", "600")}}) {
    SCOPED_TRACE(name);
    auto w = make_world(text);
    ASSERT_EQ(w->assets.sprite(w->cat.sensors[0], 0).width, 400);
    std::vector<Scenario> scenes = coverage(w->cat, 40, 4, false);
    scenes.push_back(crowded(w->cat, 0, 0));
    scenes.push_back(crowded(w->cat, 0, 7));
    const SceneBatch batch = test::batch_of(scenes, 123);
    expect_parity(*w, batch, model(81, true), name);
    expect_parity(*w, first_of(batch, 12), model(82, false, 2.0), name);
  }
}

// =============================================================================================
// 8. Huge per-pixel noise.

TEST(ExtremeNoise, SigmaOfAThousand) {
  World& w = default_world();
  const SceneBatch batch = test::batch_of(coverage(w.cat, 20, 6, false), 31);
  // The block-mean model ignores clipping, which dominates at this sigma: the fast tier's
  // features-only run is held to its own model only (clamped at 0 and 255).
  const auto p = expect_parity(w, batch, model(91, true, 1000.0), "sigma 1000", FastNoisy::own_model);
  auto share_at_ends = [](const BatchOutput& o) {
    size_t ends = 0, all = 0;
    for (const std::vector<uint8_t>* v : {&o.view("upper").pixels, &o.view("lower").pixels, &o.view("ir").pixels}) {
      for (uint8_t x : *v) ends += x == 0 || x == 255;
      all += v->size();
    }
    return all ? double(ends) / all : 0.0;
  };
  EXPECT_GT(share_at_ends(p->ref_images), 0.85);
  for (size_t t = 0; t < kTiers.size(); ++t) EXPECT_GT(share_at_ends(p->images[t]), 0.85) << tier_name(kTiers[t]);
}

// =============================================================================================
// 8b. The physics model: the coverage set (every variant in every region, then crowds) in
// every tier, images and features-only runs (the fast tier's raw-grid path), with jitter
// and block sizes from one pixel to beyond the image.

TEST(ExtremePhysics, CoverageSetInEveryTier) {
  World& w = default_world();
  const SceneBatch batch = test::batch_of(test::parity_set(w.cat, 200, 13), 77);
  expect_parity(w, batch, physics_model(201, 10, 5), "physics model, coverage set");
  ModelSettings jitter = physics_model(202);
  jitter.jitter = 5.5;
  expect_parity(w, first_of(batch, 80), jitter, "physics model, jitter");
  for (int block : {1, 7, 300})
    expect_parity(w, first_of(batch, 40), physics_model(203, block), "physics model, block");
}

// =============================================================================================
// 9. The largest seeds and scenario indices.

TEST(ExtremeSeeds, ZeroAndMaxSeedsAndIndicesNearTheEnd) {
  World& w = default_world();
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 10; ++k) scenes.push_back(test::random_scenario(w.cat, k + 500, 6));
  for (const uint64_t seed : {uint64_t{0}, kMaxU64})
    for (const uint64_t first : {uint64_t{0}, kMaxU64 - 9}) {
      const SceneBatch batch = test::batch_of(scenes, first);
      const ModelSettings m = model(seed, true, 5.0, 10, 7);
      SCOPED_TRACE(describe(m) + ", first index " + std::to_string(first));
      const auto p = expect_parity(w, batch, m, "extreme seed and index");
      expect_parity(w, batch, physics_model(seed, 10, 7), "physics model, extreme seed and index");
      for (size_t t = 0; t < kTiers.size(); ++t) {
        const std::string who = tier_name(kTiers[t]);
        // Same inputs, same bytes.
        BatchOutput again;
        w.cl->run(batch, images_plan(m, kTiers[t]), again);
        EXPECT_TRUE(again.view("upper").pixels == p->images[t].view("upper").pixels &&
                    again.view("lower").pixels == p->images[t].view("lower").pixels &&
                    again.view("ir").pixels == p->images[t].view("ir").pixels)
            << who << ": images differ between two identical runs";
        EXPECT_TRUE(again.features == p->images[t].features) << who;
        EXPECT_TRUE(again.metal == p->images[t].metal) << who;
        w.cl->run(batch, features_plan(m, kTiers[t]), again);
        EXPECT_TRUE(again.features == p->features[t].features) << who << ": features-only run not repeatable";
        // The last scenario alone, as the first of its own batch.
        BatchOutput one;
        w.cl->run(test::batch_of({scenes[9]}, first + 9), images_plan(m, kTiers[t]), one);
        const size_t px = size_t(one.view("upper").width) * one.view("upper").height;
        ASSERT_EQ(one.view("upper").pixels.size(), px);
        EXPECT_TRUE(std::equal(one.view("upper").pixels.begin(), one.view("upper").pixels.end(),
                               p->images[t].view("upper").of(9)))
            << who;
        EXPECT_TRUE(std::equal(one.metal.begin(), one.metal.end(), p->images[t].metal_of(9))) << who;
      }
    }
  // The seed matters at the top of its range too.
  BatchOutput a, b;
  const SceneBatch batch = test::batch_of(scenes, kMaxU64 - 9);
  w.cl->run(batch, images_plan(model(0, true, 5.0), Tier::standard), a);
  w.cl->run(batch, images_plan(model(kMaxU64, true, 5.0), Tier::standard), b);
  EXPECT_NE(a.view("upper").pixels, b.view("upper").pixels);
}

// =============================================================================================
// 10. Batches of one and of a million.

TEST(ExtremeBatch, OneAndAMillion) {
  World& w = default_world();
  const ModelSettings m = model(1234, true, 0.0, 100, 5);
  const Plan plan = features_plan(m, Tier::standard);
  ASSERT_EQ(test::features_path(*w.cl, plan), "thesis_sparse_features");
  constexpr size_t kMillion = 1000000;
  SceneBatch big(kBuiltinRegions);
  big.first_index = 0;
  big.subject.reserve(kMillion);
  big.objects.reserve(kMillion * kBuiltinRegions);
  big.label.reserve(kMillion);
  for (uint64_t k = 0; k < kMillion; ++k) big.push(test::random_scenario(w.cat, k, 4));
  BatchOutput out;
  w.cl->run(big, plan, out);
  const size_t F = out.layout.image_features();
  ASSERT_EQ(F, size_t(2 * 2 * 2 + kBuiltinRegions));
  ASSERT_EQ(out.features.size(), kMillion * F);
  ASSERT_EQ(out.metal.size(), kMillion * kBuiltinZones);
  expect_in_range(out);
  for (const uint64_t index : {uint64_t{0}, uint64_t{1}, uint64_t{500000}, uint64_t{999999}}) {
    SCOPED_TRACE("index " + std::to_string(index));
    const SceneBatch one = test::batch_of({big.at(index)}, index);
    BatchOutput alone, ref;
    w.cl->run(one, plan, alone);
    ASSERT_EQ(alone.features.size(), F);
    EXPECT_TRUE(std::equal(alone.features.begin(), alone.features.end(), out.features_of(index)))
        << "features of the scenario alone differ from its row in the million";
    EXPECT_TRUE(std::equal(alone.metal.begin(), alone.metal.end(), out.metal_of(index)));
    w.ref->run(one, plan, ref);
    EXPECT_EQ(check_tolerance(compare_outputs(alone, ref), tier_tolerance(Tier::standard)), "");
  }
}

// =============================================================================================
// 11. Sums over large blocks: fp32 against fp64.

TEST(ExtremeLargeSums, BlockOf4096OverA4096Image) {
  {
    // Per-scenario content (procedural body, objects, pattern noise): within tolerance.
    World& w = world_4096();
    const SceneBatch batch = test::batch_of({three_scenes_4096(w.cat)[2]}, 3);
    const auto p = expect_parity(w, batch, model(111, true, 0.0, 4096), "4096 image, block 4096");
    EXPECT_EQ(p->ref_features.layout.grids[0].blocks_x, 1);
  }
  // All white, with regions 1 and 7 the whole view: every mean is exactly 255, though the sum
  // (255 * 4096^2) is above 2^31 and far above 2^24. Block 256 takes the sparse path.
  TempDir t;
  const std::string white = write_gray(t.path(), "white.png", 4096, 4096, 255);
  const std::string white_ir = write_gray(t.path(), "white-ir.png", 2048, 4096, 255);
  std::string text = first_subject_only(default_text());
  text = set_view_sizes(text, 4096, 4096, 2048, 4096);
  text = map_rects(text, [](int region, bool mmw, Rect r) {
    if (region == 1 || region == 7) return mmw ? Rect{0, 0, 4096, 4096} : Rect{0, 0, 2048, 4096};
    return Rect{r.x * 20, r.y * 20, r.w * 20, r.h * 20};
  });
  text = add_after_name(text, "subject-1", subject_images(white, white, white_ir));
  auto w = make_world(text, t.str());
  std::vector<Scenario> scenes(2);  // empty, then objects over the white
  for (int r : {0, 3, 6, 9, 12}) scenes[1].objects[r] = static_cast<int16_t>(r % w->cat.variant_list.size());
  const SceneBatch batch = test::batch_of(scenes, 0);
  // Under the sanitizers (test::kSanitized) the dense path's block only: the sparse path's
  // host code is theirs on smaller views.
  for (int block : test::kSanitized ? std::vector<int>{4096} : std::vector<int>{4096, 256}) {
    const auto p = expect_parity(*w, batch, model(112, true, 0.0, block), "white 4096 image");
    SCOPED_TRACE("block " + std::to_string(block));
    for (const BatchOutput* o : {&p->ref_images, &p->ref_features, &p->images[0], &p->images[1], &p->images[2],
                                 &p->features[0], &p->features[1], &p->features[2]}) {
      ASSERT_EQ(o->features.size(), 2 * size_t(o->layout.image_features()));
      size_t not_white = 0;
      for (int k = 0; k < o->layout.image_features(); ++k) not_white += o->features_of(0)[k] != 255.0f;
      EXPECT_EQ(not_white, 0u) << "means of an all-white scenario that are not exactly 255";
      EXPECT_LT(o->features_of(1)[2 * o->layout.grids[0].blocks_x * o->layout.grids[0].blocks_y], 255.0f)
          << "objects show";
    }
  }
}

// =============================================================================================
// 12. NaN, infinity and negative numbers are rejected, naming file, line and field.

TEST(ExtremeRejection, CatalogueNumbers) {
  const std::string zones =
      "base_zones = [200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200]";
  struct Case {
    std::string from, to, field;
    std::vector<std::string> extra;
  };
  const std::vector<Case> cases = {
      {"alpha = 0.9", "alpha = nan", "images.alpha", {"NaN"}},
      {"alpha = 0.9", "alpha = inf", "images.alpha", {"infinity"}},
      {"alpha = 0.9", "alpha = -inf", "images.alpha", {"infinity"}},
      {"alpha = 0.9", "alpha = -0.1", "images.alpha", {"-0.1"}},
      {"build = 1.0", "build = nan", "subjects[1].build", {"NaN"}},
      {"build = 1.0", "build = -inf", "subjects[1].build", {"infinity"}},
      {"build = 1.0", "build = -1.0", "subjects[1].build", {"-1"}},
      {zones, replace_once(zones, "[200, 200", "[200, -5"), "subjects[1].base_zones[1]", {"-5"}},
      {"size = [44, 30]", "size = [-3, 4]", "objects[1].size[0]", {"-3"}},
      {"size = [44, 30]", "size = [44, -30]", "objects[1].size[1]", {"-30"}},
      {"gain = 1.0", "gain = -1", "noise[1].gain", {"-1"}},
      {"gain = 1.0", "gain = inf", "noise[1].gain", {"infinity"}},
      {"gain = 1.0", "gain = nan", "noise[1].gain", {"NaN"}},
      {"size = [200, 200]", "size = [-200, 200]", "views[1].size[0]", {"-200"}},
      {"noise_size = 40", "noise_size = -40", "images.noise_size", {"-40"}},
      {"mmw_level = 238", "mmw_level = -1", "objects[1].mmw_level", {"-1"}},
      {"upper = [49, 40, 34, 70]", "upper = [-1, 40, 34, 70]", "regions[1].rects.upper", {}},
  };
  for (const Case& c : cases) {
    const std::string text = replace_once(default_text(), c.from, c.to);
    const int line = line_of(text, c.to);
    ASSERT_GT(line, 0);
    SCOPED_TRACE(c.to);
    try {
      parse_catalogue(text, "test.toml", "", "");
      ADD_FAILURE() << "accepted: " << c.to;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_TRUE(has(msg, "test.toml:" + std::to_string(line) + ":")) << msg;
      EXPECT_TRUE(has(msg, c.field)) << msg;
      for (const std::string& x : c.extra) EXPECT_TRUE(has(msg, x)) << msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an InputError: " << e.what();
    }
  }
}

TEST(ExtremeRejection, SpecFileNumbers) {
  TempDir t;
  struct Case {
    std::string line, key;
  };
  const std::vector<Case> cases = {
      {"pixel_noise = nan", "pixel_noise"},
      {"pixel_noise = -1", "pixel_noise"},
      {"pixel_noise = inf", "pixel_noise"},
      {"pixel_noise = -inf", "pixel_noise"},
      {"pixel_noise = -0.5", "pixel_noise"},
      {"count = -1", "count"},
      {"metal_noise = -2", "metal_noise"},
      {"block = -5", "block"},
      {"seed = -1", "seed"},
  };
  std::vector<Rejection> rejections;
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path spec = t.path() / ("spec" + std::to_string(i) + ".toml");
    // The bad value on line 3; a harmless key before it.
    spit(spec, std::string("# extreme value\n") + (cases[i].key == "count" ? "what = \"features\"\n" : "count = 10\n") +
                   cases[i].line + "\n");
    rejections.push_back({{"generate", "--spec", spec.string()}, {spec.string() + ":3: " + cases[i].key}});
  }
  expect_all_rejected(rejections);
}

TEST(ExtremeRejection, CommandLineNumbers) {
  std::vector<Rejection> cases;
  for (const auto& [flag, value] : std::vector<std::pair<std::string, std::string>>{{"--pixel-noise", "nan"},
                                                                                    {"--pixel-noise", "-1"},
                                                                                    {"--pixel-noise", "inf"},
                                                                                    {"--pixel-noise", "-inf"},
                                                                                    {"--block", "-5"},
                                                                                    {"--block", "0"},
                                                                                    {"--metal-noise", "-1"}}) {
    cases.push_back({{"simulate", "gun", flag, value}, {flag}});
    if (value != "inf" && value != "-inf") cases.push_back({{"generate", "--count", "5", flag, value}, {flag}});
  }
  // The value as typed, not as wrapped to an unsigned 64-bit integer.
  cases.push_back({{"generate", "--count", "-1"}, {"--count", "-1"}});
  expect_all_rejected(cases);
}

// =============================================================================================
// 13. Portals other than the thesis's: views, regions and pooling declared in the catalogue.

// `batch` run whole and in pieces of `step` scenarios give the same bytes: every view's
// images, the features and the zones.
void expect_split_invariant(Backend& backend, const SceneBatch& batch, const Plan& plan, size_t step) {
  BatchOutput whole, pieces, part;
  backend.run(batch, plan, whole);
  for (size_t at = 0; at < batch.size(); at += step) {
    SceneBatch b(batch.regions);
    b.first_index = batch.first_index + at;
    for (size_t i = at; i < std::min(batch.size(), at + step); ++i) b.push(batch.at(i));
    backend.run(b, plan, part);
    append_output(pieces, part);
  }
  ASSERT_EQ(pieces.views.size(), whole.views.size());
  for (size_t k = 0; k < whole.views.size(); ++k)
    EXPECT_TRUE(pieces.views[k].pixels == whole.views[k].pixels) << whole.views[k].name;
  EXPECT_EQ(pieces.features, whole.features);
  EXPECT_EQ(pieces.metal, whole.metal);
}

std::string front_back_text() { return slurp(fs::path(PORTALSIM_SOURCE_DIR) / "scenarios" / "portal-front-back.toml"); }

// Objects in every region, front and back; each scenario's objects from `first` on.
std::vector<Scenario> front_and_back_scenes(const Catalogue& c) {
  std::vector<Scenario> v = test::parity_set(c, 30, 5);
  for (int s = 0; s < 5; ++s) v.push_back(crowded(c, s, static_cast<size_t>(3 * s)));
  return v;
}

// The tabulated raw-grid features (physics model, fast tier) keep each meeting pair's
// correction per subject: crowded scenes on the catalogue's five subjects, and again on a
// catalogue that lists them in reverse order (each drawn with its own texture), give the same
// bytes subject for subject. A correction taken from another subject's table moves them.
TEST(PortalSubjects, PairCorrectionsAreEachSubjectsOwn) {
  const std::string text = default_text();
  const size_t first = text.find("[[subjects]]"), regions = text.find("# --- Regions");
  ASSERT_TRUE(first != std::string::npos && regions != std::string::npos && first < regions);
  std::vector<std::string> blocks;
  for (size_t at = first; at < regions;) {
    const size_t next = std::min(text.find("[[subjects]]", at + 1), regions);
    blocks.push_back(text.substr(at, next - at));
    at = next;
  }
  ASSERT_EQ(blocks.size(), 5u);
  std::string reversed = text.substr(0, first);
  for (size_t k = blocks.size(); k-- > 0;) reversed += blocks[k];
  reversed += text.substr(regions);
  World& w = default_world();
  World r;
  r.cat = parse_catalogue(reversed, "test.toml", "", "");
  for (int k = 0; k < 5; ++k) r.cat.subjects[k].texture = 4 - k;  // the texture of its place in the original
  ASSERT_EQ(r.cat.subjects[0].name, w.cat.subjects[4].name);
  r.assets = build_assets(r.cat);
  r.cl = make_opencl_backend(r.cat, r.assets, test::runtime());
  std::vector<Scenario> scenes, mirrored;
  for (int subject = 0; subject < 5; ++subject)
    for (size_t k = 0; k < 8; ++k) {
      scenes.push_back(crowded(w.cat, subject, 3 * k + subject));
      mirrored.push_back(scenes.back());
      mirrored.back().subject = 4 - subject;
    }
  const Plan plan = features_plan(physics_model(151), Tier::fast);
  ASSERT_EQ(w.cl->paths(plan), (std::vector<std::string>{"features: physics_raw_features (tabulated)"}));
  BatchOutput a, b;
  w.cl->run(test::batch_of(scenes, 11), plan, a);
  r.cl->run(test::batch_of(mirrored, 11), plan, b);
  ASSERT_EQ(a.features.size(), b.features.size());
  EXPECT_TRUE(a.features == b.features);
}

// The shipped front-and-back portal (scenarios/portal-front-back.toml): four MMW views, two
// of them the back's, mirrored, through both models and every tier, images and features, as
// the built-in portal is held.
TEST(PortalViews, FrontAndBackPortalMatchesTheReferenceInEveryTier) {
  auto w = make_world(front_back_text());
  ASSERT_EQ(w->cat.sensors.size(), 5u);
  EXPECT_EQ(w->cat.sensors[2].side, Side::back);
  EXPECT_TRUE(FeatureLayout::of(w->cat, 10).uniform) << "four pooled 200x200 views: the sparse paths take them";
  ASSERT_EQ(w->cat.region_count(), 19) << "the built-in 13 on the front and 6 on the back";
  const SceneBatch batch = test::batch_of(front_and_back_scenes(w->cat), 500, w->cat.region_count());
  expect_parity(*w, batch, model(131, true), "front and back, pattern noise");
  expect_parity(*w, batch, model(132, false, 4.0, 7, 3), "front and back, pixel and metal noise");
  expect_parity(*w, batch, physics_model(133), "front and back, physics");
  // Any batch split gives the same bytes.
  expect_split_invariant(*w->cl, batch, features_plan(model(134, true), Tier::standard), 7);
}

std::string portal_20x33_text() {
  return slurp(fs::path(PORTALSIM_SOURCE_DIR) / "tests" / "portals" / "portal-20x33.toml");
}

// The test portal of tests/portals/portal-20x33.toml (tools/portal_catalogues.py): front and
// back MMW and IR views, 20 regions and a 33-zone metal detector, declared as catalogue
// entries only. Both models and every tier, images and features, against the reference; any
// batch split gives the same bytes.
TEST(PortalCounts, TwentyRegionsAndThirtyThreeZonesMatchTheReference) {
  auto w = make_world(portal_20x33_text());
  ASSERT_EQ(w->cat.region_count(), 20);
  ASSERT_EQ(w->cat.zones, 33);
  ASSERT_EQ(w->cat.sensors.size(), 6u);
  EXPECT_EQ(w->cat.sensors[5].name, "back_ir");
  EXPECT_EQ(w->cat.sensors[5].side, Side::back);
  EXPECT_EQ(w->cat.sensors[2].raw, (std::array<int, 2>{24, 24})) << "the back MMW camera's own raw grid";
  // Random crowds (a quarter under the sanitizers, test::kSanitized, like the other parity
  // tests' random scenarios), then every region filled on each subject.
  std::vector<Scenario> scenes = coverage(w->cat, test::kSanitized ? 6 : 24, 10, false);
  for (int s = 0; s < 5; ++s) scenes.push_back(crowded(w->cat, s, static_cast<size_t>(2 * s)));
  const SceneBatch batch = test::batch_of(scenes, 700, w->cat.region_count());
  expect_parity(*w, batch, model(161, true), "20 regions, pattern noise");
  expect_parity(*w, batch, model(162, false, 4.0, 7, 3), "20 regions, pixel and metal noise");
  const auto physics = expect_parity(*w, batch, physics_model(163), "20 regions, physics");
  // Region 20 (the back of the neck, seen only from behind) and zones past the 19th count.
  const BatchOutput& o = physics->images[1];
  ASSERT_EQ(o.metal.size(), batch.size() * 33);
  EXPECT_EQ(o.layout.image_features(), o.layout.block_features() + 20);
  size_t late_zones = 0;
  for (size_t i = 0; i < batch.size(); ++i)
    for (int z = 19; z < 33; ++z) late_zones += o.metal_of(i)[z] < 200;
  EXPECT_GT(late_zones, 0u) << "zones 20-33 never read metal";
  Scenario neck;
  neck.objects[19] = static_cast<int16_t>(test::variant_of(w->cat, "gun"));
  BatchOutput bare, gun;
  const Plan plan = images_plan(physics_model(164), Tier::standard);
  w->cl->run(test::batch_of({Scenario{}}, 0, 20), plan, bare);
  w->cl->run(test::batch_of({neck}, 0, 20), plan, gun);
  EXPECT_EQ(bare.view("upper").pixels, gun.view("upper").pixels) << "the back of the neck is not seen from the front";
  EXPECT_NE(bare.view("back_upper").pixels, gun.view("back_upper").pixels);
  EXPECT_NE(bare.view("back_ir").pixels, gun.view("back_ir").pixels);
  EXPECT_NE(bare.metal, gun.metal);
  // Any batch split gives the same bytes: images of every view, features and zones.
  expect_split_invariant(*w->cl, batch, images_plan(model(165, true, 2.0, 10, 2), Tier::standard), 6);
}

// Regions and zones past the capacities (kernels/contract.h), and tables that disagree with
// the counts, are refused naming the file, line and field.
TEST(PortalCounts, CountsPastTheCapacitiesAreRefusedNamingTheField) {
  const std::string text = portal_20x33_text();
  std::string extra;
  for (int r = 21; r <= kMaxRegions + 1; ++r)
    extra += "[[regions]]\nname = \"extra-" + std::to_string(r) + "\"\nrects = { upper = [0, 0, 10, 10] }\n\n";
  struct Case {
    std::string text, field, says;
  };
  const std::vector<Case> cases{
      {replace_once(text, "# --- Objects", extra + "# --- Objects"), "regions",
       "expected 1 to " + std::to_string(kMaxRegions) + " regions, found " + std::to_string(kMaxRegions + 1)},
      {replace_once(text, "zones = 33", "zones = " + std::to_string(kMaxZones + 1)), "metal.zones", "out of range"},
      {replace_once(text, "zones = 33", "zones = 19"), "metal.influence.none[region 1]",
       "expected 19 values, found 33"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.field);
    expect_refused(c.text, c.field, c.says);
  }
  // A [metal.physics] of another zone count: its first per-zone array names it.
  std::string physics = text;
  const size_t at = physics.find("tx_panel = [\"a\", ");
  ASSERT_NE(at, std::string::npos);
  physics.replace(at, std::string("tx_panel = [\"a\", ").size(), "tx_panel = [");
  try {
    parse_catalogue(physics, "test.toml", "", "");
    ADD_FAILURE() << "accepted 32 panels for 33 zones";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("metal.physics.tx_panel: expected an array of 33 panels"), std::string::npos)
        << e.what();
  }
}

// A view's own camera ([[views]] netd, raw): the catalogue's upper view keeps its raw grid
// and NETD whatever the run's --mmw-raw and --netd, the IR view its NETD over --ir-netd; the
// other views follow the run. Each view's image is the one a run with its numbers as the
// knobs gives, on both backends.
std::string own_cameras_text(const std::string& upper, const std::string& ir) {
  return test::with_view_line(test::with_view_line(default_text(), "upper", upper), "ir", ir);
}

TEST(PortalCameras, AViewsOwnRawGridAndNetdHoldOverTheRunsKnobs) {
  auto own = make_world(own_cameras_text("raw = [20, 24]\nnetd = 1.5\n", "netd = 0.0\n"));
  ASSERT_EQ(own->cat.sensors[0].raw, (std::array<int, 2>{20, 24}));
  ASSERT_EQ(own->cat.sensors[0].netd, 1.5);
  ASSERT_FALSE(own->cat.sensors[1].netd.has_value());
  World& plain = default_world();
  // Under the sanitizers a third of the scenarios: the reference's loops are the time.
  const size_t scenes = test::kSanitized ? 4 : 12;
  const SceneBatch batch = test::batch_of(coverage(own->cat, scenes, 4, false), 300);
  ModelSettings run = physics_model(171);
  run.netd = 4.0;
  run.ir_netd = 0.3;
  // The upper view as a run of --mmw-raw 20x24 --netd 1.5 gives it; the IR view as one
  // of --ir-netd 0; the lower view as the run's knobs give it.
  ModelSettings upper_knobs = run, ir_knobs = run;
  upper_knobs.raw_width = 20;
  upper_knobs.raw_height = 24;
  upper_knobs.netd = 1.5;
  ir_knobs.ir_netd = 0;
  // Under the sanitizers one tier too.
  const std::vector<Tier> tiers =
      test::kSanitized ? std::vector<Tier>{Tier::standard} : std::vector<Tier>{Tier::standard, Tier::exact};
  for (Tier tier : tiers) {
    SCOPED_TRACE(tier_name(tier));
    for (const bool reference : {false, true}) {
      SCOPED_TRACE(reference ? "reference" : "opencl");
      const auto run_on = [&](World& w, const ModelSettings& m) {
        BatchOutput o;
        (reference ? *w.ref : *w.cl).run(batch, images_plan(m, tier), o);
        return o;
      };
      const BatchOutput o = run_on(*own, run), as_upper = run_on(plain, upper_knobs), as_run = run_on(plain, run),
                        as_ir = run_on(plain, ir_knobs);
      EXPECT_TRUE(o.view("upper").pixels == as_upper.view("upper").pixels);
      EXPECT_TRUE(o.view("lower").pixels == as_run.view("lower").pixels);
      EXPECT_TRUE(o.view("ir").pixels == as_ir.view("ir").pixels);
      EXPECT_TRUE(o.view("upper").pixels != as_run.view("upper").pixels) << "the case cannot tell";
      EXPECT_TRUE(o.view("ir").pixels != as_run.view("ir").pixels) << "the case cannot tell";
    }
  }
  // Every tier against the reference, features-only paths included (the fast tier's
  // raw-grid tables are made per view), with the upper view's own raw grid: 20x24 where the
  // run's is 32x32.
  auto raw_only = make_world(own_cameras_text("raw = [20, 24]\n", ""));
  ModelSettings m = physics_model(172);
  m.raw_width = m.raw_height = 32;
  const SceneBatch singles = test::batch_of(coverage(raw_only->cat, scenes, 4, true), 310);
  ASSERT_EQ(test::features_path(*raw_only->cl, features_plan(m, Tier::fast)), "physics_raw_features");
  const auto p = expect_parity(*raw_only, singles, m, "the upper view's own raw grid");
  BatchOutput at_run;
  plain.cl->run(singles, features_plan(m, Tier::fast), at_run);
  EXPECT_TRUE(at_run.features != p->features[2].features) << "the fast tier's features ignore the view's raw grid";
}

// A view's camera numbers out of range, or a raw grid where there is none, are refused
// naming the file, line and field.
TEST(PortalCameras, BadOwnCamerasAreRefusedNamingTheField) {
  struct Case {
    std::string upper, ir, field, says;
  };
  const std::vector<Case> cases{
      {"", "raw = [20, 20]\n", "views[3].raw", "a raw grid is an MMW camera's"},
      {"raw = [201, 20]\n", "", "views[1].raw", "201x20 is finer than the view (200x200)"},
      {"raw = [20]\n", "", "views[1].raw", "expected"},
      {"netd = -1\n", "", "views[1].netd", "out of range"},
      {"", "netd = 11\n", "views[3].netd", "out of range"},
      {"netd = \"3\"\n", "", "views[1].netd", "expected a number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.field + " " + c.upper + c.ir);
    expect_refused(own_cameras_text(c.upper, c.ir), c.field, c.says);
  }
}

// A back view draws the body and the objects mirrored: the body's outline is the front's
// mirror image (its texture its own), and each object's drawing the front's, mirrored.
TEST(PortalViews, BackViewsAreMirrored) {
  auto w = make_world(front_back_text());
  const Sensor &front = w->cat.sensors[0], &back = w->cat.sensors[2];
  ASSERT_EQ(back.name, "back_upper");
  ASSERT_NE(front.sprite_set, back.sprite_set);
  for (size_t v = 0; v < w->cat.variant_list.size(); ++v) {
    const Image &a = w->assets.sprite(front, static_cast<int>(v)), &b = w->assets.sprite(back, static_cast<int>(v));
    ASSERT_EQ(a.width, b.width);
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x)
        for (int c = 0; c < 2; ++c)
          ASSERT_EQ(a.at(x, y, c), b.at(a.width - 1 - x, y, c)) << w->cat.variant_name(int(v));
  }
  const Image &f = w->assets.bases[0][0], &b = w->assets.bases[0][2];
  size_t outline_differs = 0, texture_differs = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const int a = f.at(x, y), m = b.at(f.width - 1 - x, y);
      outline_differs += (a > 90) != (m > 90);  // body (about 150) or room (about 25)
      texture_differs += a != m;
    }
  EXPECT_LT(outline_differs, 100u) << "the back's outline is the front's mirrored (edge pixels aside)";
  EXPECT_GT(texture_differs, 5000u) << "the back has its own texture";
}

// The metal detector places a back region's object where the body carries it: a back view is
// mirrored, so the back of the right knee is on the subject's right, where the front's right
// knee is. The same object there and at the front's right knee reads the same zones.
TEST(PortalViews, MetalFindsABackObjectOnTheSameSideOfThePortal) {
  auto back = make_world(front_back_text());
  // Region 18 (back of the right knee) moved to the front lower view's right knee.
  std::string text = replace_once(front_back_text(), "rects = { back_lower = [104, 80, 46, 55] }",
                                  "rects = { lower = [50, 80, 46, 55] }");
  auto front = make_world(text);
  Scenario s;
  s.objects[17] = static_cast<int16_t>(test::variant_of(back->cat, "gun"));
  const ModelSettings m = physics_model(141);
  const auto a = reference::metal_objects(back->cat, back->assets, m, s, 0);
  const auto b = reference::metal_objects(front->cat, front->assets, m, s, 0);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(a[0].x, b[0].x);
  EXPECT_EQ(a[0].z, b[0].z);
  EXPECT_LT(a[0].x, 0.0) << "the subject's right is the portal's x < 0 (panel A)";
  BatchOutput oa, ob;
  Plan plan = features_plan(m, Tier::standard);
  back->cl->run(test::batch_of({s}, 0, back->cat.region_count()), plan, oa);
  front->cl->run(test::batch_of({s}, 0, front->cat.region_count()), plan, ob);
  EXPECT_EQ(oa.metal, ob.metal);
  // The gun on the subject's right reads more on panel A's zones than on panel B's.
  int a_zones = 0, b_zones = 0;
  for (int z = 0; z < back->cat.zones; ++z)
    (back->cat.metal_physics.tx_side[z] < 0 ? a_zones : b_zones) += 200 - oa.metal[z];
  EXPECT_GT(a_zones, 0);
}

// A pooled IR view (100x200 beside the 200x200 MMW views): each pooled view has its own grid of
// blocks, the features take the rendered views, and they match the reference in every tier.
TEST(PortalViews, PooledViewsOfOtherSizesHaveTheirOwnGrids) {
  const std::string text =
      replace_once(default_text(), "field = [0, 0, 200, 400]\n", "field = [0, 0, 200, 400]\npooled = true\n");
  auto w = make_world(text);
  const FeatureLayout lay = FeatureLayout::of(w->cat, 30);
  ASSERT_EQ(lay.pooled.size(), 3u);
  EXPECT_FALSE(lay.uniform);
  EXPECT_EQ(lay.grids[2].blocks_x, 4);  // 100 = 3 x 30 + 10
  EXPECT_EQ(lay.grids[2].blocks_y, 7);  // 200 = 6 x 30 + 20
  EXPECT_EQ(lay.grids[2].offset, 2 * 49);
  EXPECT_EQ(lay.names()[2 * 49], "ir_r0_c0");
  EXPECT_EQ(lay.names()[2 * 49 + 27], "ir_r6_c3");
  const SceneBatch batch = test::batch_of(test::parity_set(w->cat, 40, 4), 900);
  expect_parity(*w, batch, model(151, true, 0.0, 30), "pooled IR");
  expect_parity(*w, batch, model(152, false, 3.0, 30), "pooled IR, pixel noise");
  expect_parity(*w, batch, physics_model(153, 30), "pooled IR, physics");
}

// A catalogue's views and regions are checked like every other field: file, line and field.
TEST(PortalViews, BadViewsAndRegionsAreRefusedNamingTheField) {
  struct Case {
    std::string from, to, field, says;
  };
  const std::vector<Case> cases{
      {"name = \"back_upper\"", "name = \"upper\"  # again", "views[3].name", "named twice"},
      {"name = \"back_upper\"", "name = \"Back Upper\"", "views[3].name", "a-z, 0-9 and _"},
      {"name = \"lower-back\"", "name = \"upper-back\"  # again", "regions[15].name", "named twice"},
      {"camera = \"ir\"", "camera = \"thermal\"", "views[5].camera", "\"mmw\" or \"ir\""},
      {"side = \"back\"", "side = \"left\"", "views[3].side", "\"front\" or \"back\""},
      {"field = [0, 200, 200, 200]", "field = [0, 200, 0, 200]", "views[2].field[2]", "out of range"},
      {"field = [0, 200, 200, 200]", "field = [0, 200]", "views[2].field", "[x, y, width, height]"},
      {"pooled = true", "pooled = 1", "views[1].pooled", "true or false"},
      {"rects = { back_upper = [66, 40, 68, 70] }", "rects = { back = [66, 40, 68, 70] }", "regions[14].rects.back",
       "not one of the catalogue's [[views]]"},
      {"rects = { back_upper = [66, 40, 68, 70] }", "rects = {}", "regions[14].rects", "at least one"},
      {"rects = { back_upper = [66, 40, 68, 70] }", "rects = { back_upper = [166, 40, 68, 70] }",
       "regions[14].rects.back_upper", "outside the 200x200 view"},
      {"name = \"subject-2\"", "name = \"subject-2\"\nimages.back = \"b.png\"", "subjects[2].images.back",
       "not one of the catalogue's [[views]]"},
      {"alpha = 0.9", "alpha = 0.9\nmmw_width = 200", "images.mmw_width", "[[views]] entries now"},
      {"name = \"seat\"", "name = \"seat\"\nview = \"lower\"", "regions[17].view", "rects = { VIEW"},
      {"field = [0, 200, 200, 200]", "field = [0, 200, 1, 1]", "views[2].field", "more than 4096 pixels long"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    const std::string text = replace_once(front_back_text(), c.from, c.to);
    const int line = line_of(text, c.to.substr(c.to.rfind('\n') == std::string::npos ? 0 : c.to.rfind('\n') + 1));
    const std::string what = expect_refused(text, c.field, c.says);
    if (c.field != "regions[14].rects" && c.field != "views[2].field") {
      EXPECT_NE(what.find("test.toml:" + std::to_string(line) + ":"), std::string::npos) << what;
    }
  }
}

// A pooled IR view is a sensor of its own to `evaluate`, and a data set is read only through
// the catalogue it was made with.
TEST(PortalViews, EvaluateReportsAPooledIrViewAndRefusesAnotherCatalogue) {
  TempDir t;
  const fs::path cat = t.path() / "ir-pooled.toml";
  spit(cat, replace_once(default_text(), "field = [0, 0, 200, 400]\n", "field = [0, 0, 200, 400]\npooled = true\n"));
  const fs::path data = t.path() / "set", report = t.path() / "report";
  const Result g = finish(start(t.path(), {"generate",  "--catalogue", cat.string(),
                                           "--count",   "400",         "--seed",
                                           "3",         "--pool",      "gun,metal-plate,mobile-phone",
                                           "--objects", "0..2",        "--rule",
                                           "gun",       "--balance",   "--what",
                                           "features",  "--format",    "csv",
                                           "--block",   "40",          "--quiet",
                                           "--out",     data.string()}));
  ASSERT_EQ(g.status, 0) << describe(g);
  EXPECT_TRUE(has(slurp(data / "features.csv").substr(0, 4096), "ir_r0_c0,")) << "IR blocks are columns";
  const Result e = finish(start(t.path(), {"evaluate", data.string(), "--catalogue", cat.string(), "--bootstrap", "50",
                                           "--no-plot", "--out", report.string()}));
  ASSERT_EQ(e.status, 0) << describe(e);
  const nlohmann::json json = nlohmann::json::parse(slurp(report / "report.json"));
  for (const char* sensor : {"upper", "lower", "ir", "metal", "fused_features"})
    EXPECT_TRUE(json["entries"].contains(sensor)) << sensor << " in report.json";
  // A carried gun shows in IR (the clothing over it cooler): its features alone tell it apart.
  EXPECT_GT(json["entries"]["ir"]["auc"].get<double>(), 0.6);
  // The same folder through the built-in catalogue: refused, nothing written.
  const fs::path other = t.path() / "other";
  const Result r = finish(start(t.path(), {"evaluate", data.string(), "--no-plot", "--out", other.string()}));
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(has(r.err, "made with the catalogue " + cat.string())) << r.err;
  EXPECT_TRUE(has(r.err, "give that catalogue with --catalogue")) << r.err;
  EXPECT_FALSE(fs::exists(other));
}

}  // namespace
}  // namespace portalsim::test
