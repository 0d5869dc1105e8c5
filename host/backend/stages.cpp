#include "backend/stages.h"

#include <stdexcept>

namespace portalsim {

const std::vector<ViewStage>& view_stages() {
  using enum StageItems;
#define PORTALSIM_STAGE_ENTRY(name, pixels, ...) ViewStage{#name, reference::name, {__VA_ARGS__}, pixels},
  static const std::vector<ViewStage> stages = {PORTALSIM_STAGES(PORTALSIM_STAGE_ENTRY)};
#undef PORTALSIM_STAGE_ENTRY
  return stages;
}

void check_chain(const Sensor& view) {
  for (Model m : {Model::thesis, Model::physics}) {
    const std::vector<std::string>& chain = view.chain_for(m);
    for (size_t k = 0; k < chain.size(); ++k)
      if (view_stage(chain[k]).makes_pixels != (k + 1 == chain.size()))
        throw std::logic_error("camera view " + view.name + ": its " + model_name(m) +
                               " chain must end with the one stage that makes pixels");
    if (chain.empty()) throw std::logic_error("camera view " + view.name + ": empty chain");
  }
}

const ViewStage& view_stage(std::string_view name) {
  for (const ViewStage& s : view_stages())
    if (s.name == name) return s;
  throw std::invalid_argument("no stage is called \"" + std::string(name) + "\"");
}

}  // namespace portalsim
