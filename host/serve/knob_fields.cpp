#include "serve/knob_fields.h"

#include <string>

#include "base/error.h"
#include "plan/knobs.h"

namespace portalsim {

namespace {

const char* kind_name(KnobKind k) {
  switch (k) {
    case KnobKind::integer:
      return "integer";
    case KnobKind::number:
      return "number";
    case KnobKind::on_off:
      return "on_off";
    case KnobKind::choice:
      return "choice";
    case KnobKind::grid:
      return "grid";
    case KnobKind::range:
      return "range";
  }
  return "number";
}

}  // namespace

nlohmann::json knob_list() {
  Plan defaults;
  defaults.fidelity = tier_fidelity(Tier::standard);
  nlohmann::json list = nlohmann::json::array();
  for (const Knob& k : knobs()) {
    // The registry's help names the knobs of the physics model ("physics: ...").
    const bool physics = k.help.rfind("physics:", 0) == 0;
    list.push_back({{"key", k.key},
                    {"flag", k.flag()},
                    {"kind", kind_name(k.kind)},
                    {"min", k.min},
                    {"max", k.max},
                    {"choices", k.choices},
                    {"unit", k.unit},
                    {"help", k.help},
                    {"values", k.values()},
                    {"default", knob_text(k.get(defaults))},
                    {"fidelity", k.fidelity},
                    {"drawable", k.drawn >= 0},  // takes A..B, drawn per scenario
                    {"group", physics ? "physics" : "both"}});
  }
  return list;
}

void apply_knobs(const nlohmann::json& request, Plan& plan) {
  for (const Knob& k : knobs()) {
    if (!request.contains(k.key) || request[k.key].is_null()) continue;
    const nlohmann::json& v = request[k.key];
    if (!v.is_string() && !v.is_number() && !v.is_boolean())
      throw InputError("request: field \"" + k.key + "\" has the wrong type");
    set_knob(plan, k, knob_text(v), k.flag());
  }
}

}  // namespace portalsim
