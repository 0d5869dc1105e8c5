// One scenario from what a user typed (subject, objects per region, rule or label): the
// checks and words of `simulate`'s command line, which `serve`'s requests share.
#pragma once
#include <string>
#include <vector>

#include "scene/catalogue.h"
#include "scene/scene.h"

namespace portalsim {

struct ScenarioInputs {
  int subject = 1;                   // 1-based, as typed
  std::vector<std::string> objects;  // tokens for the catalogue's regions in order ("none", "gun:v")
  std::string rule;                  // threat rule, or empty
  std::string threat;                // "yes" / "no" / empty; not together with rule
};

// Checks the inputs with the command line's messages (InputError) and builds the scenario.
Scenario make_scenario(const Catalogue& cat, const ScenarioInputs& in);

}  // namespace portalsim
