// The body of a POST to the page's API (/api/render, /api/save, /api/generate), read and
// checked whole before anything runs: an InputError (HTTP 400) names the field, in the
// command line's words where the field has a flag.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

#include "plan/plan.h"
#include "scene/scenario_inputs.h"

namespace portalsim {

struct Request {
  ScenarioInputs in;
  Plan plan;  // the page's knobs over the tier's fidelity; seed from `seed`
  std::string seed = "0", tier = "standard";
  std::string name;   // /api/save and /api/generate: the folder under --root (check_name)
  int64_t count = 0;  // /api/generate
  Scenario scene;     // made from `in`
};

Request parse_request(const Catalogue& cat, std::string_view body);

// One name for a folder under --root: a single path component of safe characters. Throws
// InputError starting with `what`.
std::string check_name(const std::string& name, const char* what);

}  // namespace portalsim
