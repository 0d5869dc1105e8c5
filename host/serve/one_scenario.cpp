#include "serve/one_scenario.h"

#include <chrono>
#include <filesystem>

#include "base/error.h"
#include "scene/rules.h"
#include "sink/output_folder.h"
#include "sink/stage_fields.h"
#include "sink/staging.h"

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

OneScenarioTimes write_one_scenario(const std::string& dir, Backend& backend, const Scenario& scene, const Plan& plan,
                                    const Palette& palette, const FolderOptions& opt, BatchOutput& out,
                                    const StageFieldsRequest* stages) {
  using clock = std::chrono::steady_clock;
  // The output-folder rules of generate: new or empty, locked while written.
  if (output_folder_state(dir) == FolderState::has_files)
    throw OutputError(dir + ": is not empty; choose a new folder");
  StagedFolder folder(dir);
  const FolderLock lock(dir);
  if (output_folder_state(dir) == FolderState::has_files)  // filled while this run waited for the lock
    throw OutputError(dir + ": is not empty; choose a new folder");
  SceneBatch batch;
  batch.push(scene);
  OneScenarioTimes t;
  const auto t_run = clock::now();
  backend.run(batch, plan, out);
  t.run_seconds = std::chrono::duration<double>(clock::now() - t_run).count();
  const auto t_write = clock::now();
  write_scenario_folder([&](const std::string& f) { return folder.path(f); }, out, 0, scene.label == 1, palette, opt);
  if (stages) {
    const std::string sub = folder.path("stages");
    std::error_code ec;
    if (!std::filesystem::create_directory(sub, ec)) throw OutputError(sub + ": cannot create: " + ec.message());
    write_stage_fields(sub, stages->cat, stages->assets, plan, scene, 0);
  }
  folder.commit();
  t.write_seconds = std::chrono::duration<double>(clock::now() - t_write).count();
  return t;
}

}  // namespace portalsim
