#include "scene/generator.h"

#include <algorithm>

#include "base/error.h"
#include "scene/philox.h"

namespace portalsim {

namespace {
constexpr uint32_t kMaxAttempts = 4096;  // balanced draws: rejection sampling per index
}

Generator::Generator(const Catalogue& cat, GeneratorSpec spec, uint64_t seed)
    : cat_(cat), spec_(std::move(spec)), seed_(seed) {
  if (spec_.pool.empty()) spec_.pool = cat.default_pool;
  if (spec_.subjects.empty())
    for (size_t i = 0; i < cat.subjects.size(); ++i) spec_.subjects.push_back(static_cast<int>(i));
  for (int s : spec_.subjects)
    if (s < 0 || s >= static_cast<int>(cat.subjects.size()))
      throw InputError("subjects: " + std::to_string(s + 1) + " is out of range (1 to " +
                       std::to_string(cat.subjects.size()) + ")");
  if (spec_.min_objects < 0 || spec_.max_objects > cat.region_count() || spec_.min_objects > spec_.max_objects)
    throw InputError("objects: " + std::to_string(spec_.min_objects) + ".." + std::to_string(spec_.max_objects) +
                     " must satisfy 0 <= MIN <= MAX <= " + std::to_string(cat.region_count()) + " (the regions)");
  if (!spec_.rule.empty()) rule_.emplace(cat, spec_.rule, "rule");
  if (spec_.balance) {
    if (!rule_) throw InputError("balance: needs a threat rule (--rule) to know the classes");
    // Both classes must be reachable, or rejection sampling could never finish.
    for (int want : {1, 0}) {
      bool found = false;
      for (uint64_t i = 0; i < 64 && !found; ++i)
        for (uint32_t a = 0; a < kMaxAttempts && !found; ++a) found = (*rule_)(draw_scene(i, a)) == (want == 1);
      if (!found)
        throw InputError("balance: the rule \"" + spec_.rule + "\" is never " + (want ? "true" : "false") +
                         " for scenarios drawn from this pool and object count");
    }
  }
}

Scenario Generator::draw_scene(uint64_t index, uint32_t attempt) const {
  Scenario s;
  // Element layout of the generator stream: attempt * 64 + k.
  const uint32_t e0 = attempt * 64;
  const Philox4 r = draw(seed_, index, kStreamGenerate, e0);
  s.subject = spec_.subjects[below(r[0], static_cast<uint32_t>(spec_.subjects.size()))];
  const int count = spec_.min_objects +
                    static_cast<int>(below(r[1], static_cast<uint32_t>(spec_.max_objects - spec_.min_objects + 1)));
  // Distinct regions by a partial Fisher-Yates shuffle; objects uniform over the pool,
  // variants uniform over the object's drawings.
  const int R = cat_.region_count();
  std::array<int, kMaxRegions> regions;
  for (int k = 0; k < R; ++k) regions[k] = k;
  for (int k = 0; k < count; ++k) {
    const Philox4 q = draw(seed_, index, kStreamGenerate, e0 + 1 + static_cast<uint32_t>(k));
    const int j = k + static_cast<int>(below(q[0], static_cast<uint32_t>(R - k)));
    std::swap(regions[k], regions[j]);
    const Object& o = cat_.objects[spec_.pool[below(q[1], static_cast<uint32_t>(spec_.pool.size()))]];
    const int v = o.first_variant + static_cast<int>(below(q[2], static_cast<uint32_t>(o.variants.size())));
    s.objects[regions[k]] = static_cast<int16_t>(v);
  }
  return s;
}

Scenario Generator::operator()(uint64_t index) const {
  if (!spec_.balance) {
    Scenario s = draw_scene(index, 0);
    s.label = rule_ && (*rule_)(s) ? 1 : 0;
    return s;
  }
  const bool want = index % 2 == 0;
  for (uint32_t a = 0; a < kMaxAttempts; ++a) {
    Scenario s = draw_scene(index, a);
    if ((*rule_)(s) == want) {
      s.label = want ? 1 : 0;
      return s;
    }
  }
  throw InputError("balance: no " + std::string(want ? "threat" : "non-threat") + " scenario found for index " +
                   std::to_string(index) + " in " + std::to_string(kMaxAttempts) +
                   " draws; the rule is too rare for this pool");
}

}  // namespace portalsim
