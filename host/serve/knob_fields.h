// The page's model settings come from the knob registry (plan/knobs.h): the list the page
// builds its controls from, and a request's fields read back into a plan. A knob added
// to the registry appears on the page, and is accepted from it, with no page edit.
#pragma once
#include <nlohmann/json.hpp>

#include "plan/plan.h"

namespace portalsim {

// One entry per knob, in the registry's order: key, flag, kind (integer, number, on_off,
// choice, grid, range), min and max, choices, unit, help, default (as set_knob reads it;
// a fidelity knob's is the standard tier's), fidelity (overrides the tier), and group
// ("physics" where the knob only acts under --model physics, "both" otherwise).
nlohmann::json knob_list();

// Sets each knob the request names (a field with the knob's key: a string as the flag
// takes it, a number, or true/false for on/off), checked as its flag is. Apply after the
// tier, so that a fidelity knob overrides it. Throws InputError naming the flag or field.
void apply_knobs(const nlohmann::json& request, Plan& plan);

}  // namespace portalsim
