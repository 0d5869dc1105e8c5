// One scenario (scene/scenario_inputs.h) to its folder: shared by `simulate` and `serve`,
// so both write the same bytes.
#pragma once
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/backend.h"
#include "plan/plan.h"
#include "scene/catalogue.h"
#include "scene/scenario_inputs.h"
#include "scene/scene.h"
#include "sink/scenario_folder.h"

namespace portalsim {

struct OneScenarioTimes {
  double run_seconds = 0, write_seconds = 0;
};

// What `simulate --stages` adds: every stage's field under dir/stages (sink/stage_fields.h).
struct StageFieldsRequest {
  const Catalogue& cat;
  const AssetSet& assets;
};

// Runs `scene` on `backend` (made for `cat`) and writes its folder to `dir` all or nothing.
// `out` keeps the backend's outputs (metal zones etc.) for the caller.
OneScenarioTimes write_one_scenario(const std::string& dir, const Catalogue& cat, Backend& backend,
                                    const Scenario& scene, const Plan& plan, const Palette& palette,
                                    const FolderOptions& opt, BatchOutput& out,
                                    const StageFieldsRequest* stages = nullptr);

}  // namespace portalsim
