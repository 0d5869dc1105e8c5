// The key of a table made from a plan's knobs: every knob of the registry (plan/knobs.h)
// by its value, so that a knob added later is in every key without a word here.
#pragma once
#include <string>

#include "plan/plan.h"

namespace portalsim::opencl {

// "key=value;" for every knob, then `extra` (what else the table depends on: a view, a
// program variant).
std::string table_key(const Plan& plan, const std::string& extra);

}  // namespace portalsim::opencl
