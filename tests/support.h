// Shared test fixtures: the default catalogue and its assets built once, one OpenCL
// runtime for the whole run, and random scenarios covering the catalogue.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/backend.h"
#include "backend/opencl/opencl_backend.h"
#include "base/error.h"
#include "build_config.h"
#include "plan/plan.h"
#include "scene/catalogue.h"
#include "scene/philox.h"

namespace portalsim {
// The built-in catalogue's regions and zones, which most tests are written for
// (Catalogue.DefaultHoldsTheThesisInventory checks them).
constexpr int kBuiltinRegions = 13;
constexpr int kBuiltinZones = 19;
}  // namespace portalsim

namespace portalsim::test {

inline const Catalogue& catalogue() {
  static const Catalogue c = default_catalogue();
  return c;
}
// The first MMW view that sees region r (index into Catalogue::sensors), and its rectangle.
inline int mmw_view_of(const Catalogue& cat, int r) { return first_feature_view(cat.sensors, r); }
inline const Rect& mmw_rect(const Catalogue& cat, int r) { return cat.sensors.at(mmw_view_of(cat, r)).rects[r]; }

inline const AssetSet& assets() {
  static const AssetSet a = build_assets(catalogue());
  return a;
}
inline std::shared_ptr<OpenCLRuntime> runtime() {
  static std::shared_ptr<OpenCLRuntime> rt = std::make_shared<OpenCLRuntime>();
  return rt;
}

// Scenario k of a test set: every subject, 0 to `max_objects` objects in random regions
// with random variants, all drawn from the counter generator (stream 99).
// The drawings random_scenario draws from: the default pool's objects' (the thesis's 12 in
// the built-in catalogue; every object in a catalogue without default_pool). The other
// drawings take the same code paths with other sprites; coverage() places each of them.
inline std::vector<int16_t> default_pool_variants(const Catalogue& cat) {
  std::vector<int16_t> v;
  for (size_t k = 0; k < cat.variant_list.size(); ++k)
    if (std::find(cat.default_pool.begin(), cat.default_pool.end(), cat.variant_list[k].object) !=
        cat.default_pool.end())
      v.push_back(static_cast<int16_t>(k));
  return v;
}

inline Scenario random_scenario(const Catalogue& cat, uint64_t k, int max_objects = 13) {
  Scenario s;
  const std::vector<int16_t> drawings = default_pool_variants(cat);
  const Philox4 r = draw(12345, k, 99, 0);
  s.subject = static_cast<int>(below(r[0], static_cast<uint32_t>(cat.subjects.size())));
  const int count = static_cast<int>(below(r[1], static_cast<uint32_t>(max_objects + 1)));
  for (int j = 0; j < count; ++j) {
    const Philox4 q = draw(12345, k, 99, 1 + j);
    const int region = static_cast<int>(below(q[0], static_cast<uint32_t>(cat.region_count())));
    s.objects[region] = drawings[below(q[1], static_cast<uint32_t>(drawings.size()))];
  }
  s.label = static_cast<int>(r[2] & 1);
  return s;
}

// The default catalogue's text, scenarios/catalogue.toml.
inline std::string default_catalogue_text() {
  std::ifstream in(std::string(PORTALSIM_SOURCE_DIR) + "/scenarios/catalogue.toml", std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// What parse_catalogue says of `text` read as the file `name`; empty when it is accepted.
inline std::string catalogue_error(const std::string& text, const std::string& name) {
  try {
    parse_catalogue(text, name, "");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// `text` with the first `from` replaced by `to`; a test failure where it holds none.
inline std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "the text no longer contains \"" << from << "\"; update the test";
    return text;
  }
  return text.replace(at, from.size(), to);
}

// 1-based line of the first occurrence of `needle` in `text` (0 when absent).
inline int line_of(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  if (at == std::string::npos) return 0;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

// Catalogue text `text` with `line` added to subject k's table (0-based), right after its
// build line; *at gets the added line's number.
inline std::string with_subject_line(std::string text, int k, const std::string& line, int* at = nullptr) {
  size_t p = 0;
  for (int j = 0; j <= k; ++j) p = text.find("[[subjects]]", p + 1);
  p = text.find('\n', text.find("\nbuild = ", p) + 1) + 1;
  text.insert(p, line + "\n");
  if (at) *at = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(p), '\n'));
  return text;
}

// Catalogue text `text` with `line` (ending in a newline, or empty: nothing) added to the
// [[views]] entry called `view`, right after its name line.
inline std::string with_view_line(std::string text, const std::string& view, const std::string& line) {
  const size_t name = text.find("[[views]]\nname = \"" + view + "\"");
  EXPECT_NE(name, std::string::npos) << "the catalogue has no view " << view;
  if (name == std::string::npos || line.empty()) return text;
  text.insert(text.find('\n', name + 10) + 1, line);
  return text;
}

// Every variant of the default pool's objects in every region, every other variant in
// three regions spread over the views (one object per scenario, rotating subjects), then
// random crowds of up to `max_objects` (random_scenario from k = 0) until there are `n`.
// The objects outside the default pool take the same code paths as the thesis's 12 (a
// sprite each); three regions apiece keep the singles at 266 rather than 546.
inline std::vector<Scenario> coverage(const Catalogue& c, size_t n, int max_objects, bool singles = true) {
  std::vector<Scenario> v;
  const int R = c.region_count();
  if (singles)
    for (size_t var = 0; var < c.variant_list.size(); ++var) {
      const bool every =
          std::find(c.default_pool.begin(), c.default_pool.end(), c.variant_list[var].object) != c.default_pool.end();
      for (int r = 0; r < R; ++r) {
        const int at = static_cast<int>(var) % R;
        if (!every && r != at && r != (at + 4) % R && r != (at + 9) % R) continue;
        Scenario s;
        s.subject = static_cast<int>((var + r) % c.subjects.size());
        s.objects[r] = static_cast<int16_t>(var);
        v.push_back(s);
      }
    }
  for (uint64_t k = 0; v.size() < n; ++k) v.push_back(random_scenario(c, k, max_objects));
  return v;
}

// The scenarios of an image test that runs the fp64 reference over several plans; under
// the sanitizers, whose reference loops run several times slower, a quarter of them.
inline const size_t kImageScenes = kSanitized ? 12 : 48;

// coverage(c, n, max_objects), or under the sanitizers every fourth of its scenarios.
inline std::vector<Scenario> parity_set(const Catalogue& c, size_t n, int max_objects) {
  std::vector<Scenario> all = coverage(c, n, max_objects);
  if (!kSanitized) return all;
  std::vector<Scenario> share;
  for (size_t i = 0; i < all.size(); i += 4) share.push_back(all[i]);
  return share;
}

// The physics model's plan at its defaults but for the camera's frames and window, with a
// run seed.
inline Plan physics_plan(uint64_t seed = 7) {
  Plan p;
  p.model.model = Model::physics;
  p.model.seed = seed;
  // One NETD draw per raw pixel and a window wide enough that noise is seldom clipped, as
  // the noise tests' formulas have it.
  p.model.frames = 1;
  p.model.window_lo = 285;
  p.model.window_hi = 305;
  return p;
}

// The camera parity the physics tests hold the kernels to on their scenes, tighter than the
// tier table's bound for any scene (host/plan/tolerance.h): the MMW chain ends in one
// rounding of the displayed value, IR in one of the temperature index, so a pixel may be
// off by one level where the fp32 kernels and the fp64 reference fall either side of a
// half, and at most 0.5% of a camera's pixels do.
// (A template over compare.h's ImageDiff: this header, in the tests' precompiled header,
// leaves compare.h to the files that compare.)
template <class CameraDiff>
void expect_camera_parity(const CameraDiff& camera) {
  EXPECT_LE(camera.max_abs, 1);
  EXPECT_LE(camera.share_differing, 0.005);
}

// The features path `b` takes for `plan`, as --timing names it, without its variant:
// "physics_raw_features", "thesis_sparse_features" or Backend::kPooledFeatures.
inline std::string features_path(const Backend& b, const Plan& plan) {
  for (const std::string& p : b.paths(plan))
    if (p.rfind("features: ", 0) == 0)
      return p.substr(10, p.find(" (") == std::string::npos ? std::string::npos : p.find(" (") - 10);
  return "";
}

// The first drawing of the object called `name`; -1 (and a test failure) when none is.
inline int variant_of(const Catalogue& cat, const std::string& name) {
  const int o = cat.find_object(name);
  if (o < 0) ADD_FAILURE() << "no object called " << name;
  return o < 0 ? -1 : cat.objects[o].first_variant;
}

// A batch of scenarios of a catalogue of `regions` regions (the built-in one's by default).
inline SceneBatch batch_of(const std::vector<Scenario>& scenes, uint64_t first_index = 0,
                           int regions = kBuiltinRegions) {
  SceneBatch b(regions);
  b.first_index = first_index;
  for (const Scenario& s : scenes) {
    for (int r = regions; r < kMaxRegions; ++r)
      if (s.objects[r] != kNoObject)
        ADD_FAILURE() << "an object in region " << r + 1 << " of a " << regions << "-region batch";
    b.push(s);
  }
  return b;
}

// Scenario s's metal zones from backend b under model m (no images, no features).
inline std::vector<int> metal_zones(Backend& b, const Scenario& s, const ModelSettings& m) {
  Plan plan;
  plan.images = 0;
  plan.features = false;
  plan.model = m;
  BatchOutput out;
  b.run(batch_of({s}), plan, out);
  return std::vector<int>(out.metal.begin(), out.metal.end());
}

// A suite run once per backend, "reference" or "opencl" (INSTANTIATE_TEST_SUITE_P with both
// names), over the default catalogue.
class BothBackends : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<Backend> backend() {
    if (GetParam() == "reference") return make_reference_backend(catalogue(), assets());
    return make_opencl_backend(catalogue(), assets(), runtime());
  }
};

}  // namespace portalsim::test
