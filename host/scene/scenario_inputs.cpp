#include "scene/scenario_inputs.h"

#include "base/error.h"
#include "scene/rules.h"

namespace portalsim {

Scenario make_scenario(const Catalogue& cat, const ScenarioInputs& in) {
  Scenario scene = parse_object_list(cat, in.objects);
  const int subjects = static_cast<int>(cat.subjects.size());
  if (in.subject < 1 || in.subject > subjects)
    throw InputError("--subject: " + std::to_string(in.subject) + " is out of range (1 to " + std::to_string(subjects) +
                     ")");
  scene.subject = in.subject - 1;
  if (!in.rule.empty() && !in.threat.empty()) throw InputError("--rule and --threat: give one or the other");
  if (!in.threat.empty() && in.threat != "yes" && in.threat != "no")
    throw InputError("--threat: " + in.threat + " not in {yes,no}");  // CLI11's words
  if (!in.rule.empty())
    scene.label = ThreatRule(cat, in.rule)(scene) ? 1 : 0;
  else
    scene.label = in.threat == "yes" ? 1 : 0;
  return scene;
}

}  // namespace portalsim
