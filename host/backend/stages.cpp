#include "backend/stages.h"

#include <stdexcept>

namespace portalsim {

const std::vector<ViewStage>& view_stages() {
  static const std::vector<ViewStage> stages = {
      {"composite", reference::composite},
      {"pattern_noise", reference::pattern_noise},
      {"sensor_noise", reference::sensor_noise},
      {"display", reference::display},
  };
  return stages;
}

const std::vector<std::string>& fused_chain() {
  static const std::vector<std::string> chain = {"composite", "pattern_noise", "sensor_noise", "display"};
  return chain;
}

void check_chain(const Sensor& view) {
  if (view.chain.empty() || view.chain.back() != "display")
    throw std::logic_error("camera view " + view.name + ": its chain must end with display");
  for (const std::string& name : view.chain) view_stage(name);
}

const ViewStage& view_stage(std::string_view name) {
  for (const ViewStage& s : view_stages())
    if (s.name == name) return s;
  throw std::invalid_argument("no stage is called \"" + std::string(name) + "\"");
}

}  // namespace portalsim
