// Scenario generators: scenario i is a pure function of (seed, i, spec), so any index
// range can be made on its own (batches, shards, resume) with identical results.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "scene/rules.h"
#include "scene/scene.h"

namespace portalsim {

struct GeneratorSpec {
  std::vector<int> pool;  // object indices to draw from; empty = every object
  int min_objects = 0, max_objects = 4;
  std::vector<int> subjects;  // 0-based; empty = every subject
  std::string rule;           // threat rule; empty = every scenario is "no"
  bool balance = false;       // even indices are threats, odd are not (needs a rule)
};

class Generator {
 public:
  // Checks the spec against the catalogue (and, with balance, that the rule can be both
  // true and false with this pool); throws InputError naming the option.
  Generator(const Catalogue& cat, GeneratorSpec spec, uint64_t seed);
  Scenario operator()(uint64_t index) const;
  const GeneratorSpec& spec() const { return spec_; }

 private:
  Scenario draw_scene(uint64_t index, uint32_t attempt) const;
  const Catalogue& cat_;
  GeneratorSpec spec_;
  uint64_t seed_;
  std::optional<ThreatRule> rule_;
};

// What a listed scenario's row records of its randomised objects (the columns rotation1..13,
// scale1..13, flip1..13 that scenarios.csv holds when they are on), to be checked
// against the draws of the run that re-makes it; `where` is "file:line".
struct ListedTransforms {
  std::string where;
  std::array<ObjectTransform, kRegions> t;  // identity where the region has no object
};

// An explicit list: CSV with a header naming subject, region1..region13 and optionally
// label (yes/no/positive/negative/1/0), index (ignored: scenario i of the list is index i)
// and the randomised objects' columns, all 39 or none; with them, `transforms` (if given)
// gets one entry per scenario. Subjects are 1-based. Errors name file, line, column.
std::vector<Scenario> read_scenario_file(const Catalogue& cat, const std::string& path,
                                         std::vector<ListedTransforms>* transforms = nullptr);
// The same from text already read; `path` names it in errors. Fields hold at most
// kMaxFieldBytes.
inline constexpr size_t kMaxFieldBytes = 256;
std::vector<Scenario> parse_scenario_list(const Catalogue& cat, std::string_view text, const std::string& path,
                                          std::vector<ListedTransforms>* transforms = nullptr);

}  // namespace portalsim
