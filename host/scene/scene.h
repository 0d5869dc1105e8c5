// Scenarios and the structure-of-arrays batch that the backends consume.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/catalogue.h"

namespace portalsim {

constexpr int16_t kNoObject = -1;

// The columns of scenarios.csv and data.h5 that record a scenario's MMW raw grid where a run
// draws it from a list (raw_grid_at, plan.h).
inline constexpr std::array<const char*, 2> kRawGridColumns{"mmw_raw_width", "mmw_raw_height"};

struct Scenario {
  int subject = 0;  // 0-based
  // Variant id per region, kNoObject for none and past the catalogue's regions.
  std::array<int16_t, kMaxRegions> objects;
  int label = 0;  // 1 threat, 0 not
  Scenario() { objects.fill(kNoObject); }
};

// A randomised object's turn, scale and mirror (plan.h, object_transform draws it).
struct ObjectTransform {
  double rotation = 0.0;  // degrees, counter-clockwise in the image
  double scale = 1.0;
  bool flip = false;  // mirrored left to right (before the rotation)
  bool operator==(const ObjectTransform&) const = default;
};

// n scenarios with global indices first_index .. first_index + n - 1, or where `indices` is
// not empty, those (a backend's part of a batch: scenarios of one drawn raw grid). The index,
// not the position in the batch, feeds the random generator, so results never depend on
// batching.
struct SceneBatch {
  explicit SceneBatch(int regions) : regions(regions) {}
  int regions;  // the catalogue's regions: the stride of `objects`
  uint64_t first_index = 0;
  std::vector<uint64_t> indices;  // empty, or n: each scenario's index
  std::vector<uint8_t> subject;   // n
  std::vector<int16_t> objects;   // n * regions, region-major within a scenario
  std::vector<uint8_t> label;     // n
  // Per-scenario bodies (scene/bodies.h): each scenario's body as drawn (Subject::drawn);
  // `subject` is then its place in the body page. Empty for a run's own subjects.
  std::vector<std::string> bodies;

  size_t size() const { return subject.size(); }
  bool own_bodies() const { return !bodies.empty(); }
  uint64_t index_of(size_t i) const { return indices.empty() ? first_index + i : indices[i]; }
  void clear() {
    indices.clear();
    subject.clear();
    objects.clear();
    label.clear();
    bodies.clear();
  }
  void push(const Scenario& s) {
    subject.push_back(static_cast<uint8_t>(s.subject));
    objects.insert(objects.end(), s.objects.begin(), s.objects.begin() + regions);
    label.push_back(static_cast<uint8_t>(s.label));
  }
  Scenario at(size_t i) const {
    Scenario s;
    s.subject = subject[i];
    for (int r = 0; r < regions; ++r) s.objects[r] = objects[i * regions + r];
    s.label = label[i];
    return s;
  }
};

// Parses the thesis's command line: an object token per region in order (at most the
// catalogue's regions), "none" for an empty region, "name:v" / "name:h" for a variant.
// `where` prefixes errors (e.g. "argument 3" or "scenes.csv:12: region3").
int16_t parse_object_token(const Catalogue& cat, const std::string& token, const std::string& where);
// The objects a pool or rule token names (docs/model/objects.md): "class:NAME" (every
// object of that class), "family:NAME", "all" (with `allow_all`), or one object's name or
// alias; in catalogue order. Throws InputError naming `where` for a name nothing carries.
std::vector<int> parse_object_set(const Catalogue& cat, const std::string& token, const std::string& where,
                                  bool allow_all);
// Whether `token` names a class or family ("class:..." or "family:...", any case).
bool is_object_set_token(const std::string& token);
// The tokens of simulate's positional argument `objects`: errors start "objects: region N"
// (the command line names the argument, so that an unknown object there is a usage error).
Scenario parse_object_list(const Catalogue& cat, const std::vector<std::string>& tokens);

}  // namespace portalsim
