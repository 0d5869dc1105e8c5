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
  std::vector<int> pool;  // object indices to draw from; empty = the catalogue's default_pool
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

}  // namespace portalsim
