// The stages of a camera view's chain, each registered once under one name: its plain
// double-precision reference function (backend/reference/), its kernel (kernels/, named
// stage_<name>), its test and its benchmark. A sensor's chain (scene/sensor.h) lists
// stage names; both backends run the chain through this table. A new stage is its
// reference file, its kernel and its line in reference/stage_list.h. The OpenCL backend's
// fast paths declare which chains they implement (backend/opencl/paths/).
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "backend/reference/stages.h"

namespace portalsim {

// What one launch of a stage kernel covers: a work-item per (scenario, view row), per
// (scenario, raw-grid row) or per scenario (the whole view).
enum class StageItems { view_rows, raw_rows, scenarios };

struct StageKernel {
  std::string_view kernel;
  StageItems items;
};

struct ViewStage {
  std::string_view name;
  void (*reference)(const reference::ViewScene&, reference::Field&);
  // Its kernels, launched in order; most stages have one, stage_<name>.
  std::vector<StageKernel> kernels;
  bool makes_pixels = false;  // the last stage of every chain: the stored 8-bit pixels
};

const std::vector<ViewStage>& view_stages();
// Throws std::logic_error unless every stage of each of the view's chains is registered
// and each chain ends with a stage that makes pixels, and no other stage does.
void check_chain(const Sensor& view);
// Throws std::invalid_argument for a name no stage has.
const ViewStage& view_stage(std::string_view name);

}  // namespace portalsim
