#include "serve/one_scenario.h"

#include <chrono>
#include <filesystem>

#include "base/error.h"
#include "sink/output_folder.h"
#include "sink/stage_fields.h"
#include "sink/staging.h"

namespace portalsim {

OneScenarioTimes write_one_scenario(const std::string& dir, const Catalogue& cat, Backend& backend,
                                    const Scenario& scene, const Plan& plan, const Palette& palette,
                                    const FolderOptions& opt, BatchOutput& out, const StageFieldsRequest* stages) {
  using clock = std::chrono::steady_clock;
  // The output-folder rules of generate: new or empty, locked while written.
  if (output_folder_state(dir) == FolderState::has_files)
    throw OutputError(dir + ": is not empty; choose a new folder");
  StagedFolder folder(dir);
  const FolderLock lock(dir);
  if (output_folder_state(dir) == FolderState::has_files)  // filled while this run waited for the lock
    throw OutputError(dir + ": is not empty; choose a new folder");
  SceneBatch batch(cat.region_count());
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
