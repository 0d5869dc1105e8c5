#include "backend/stages.h"

#include <stdexcept>

namespace portalsim {

const std::vector<ViewStage>& view_stages() {
  using K = StageItems;
  static const std::vector<ViewStage> stages = {
      // The thesis model.
      {"composite", reference::composite, {{"stage_composite", K::view_rows}}},
      {"pattern_noise", reference::pattern_noise, {{"stage_pattern_noise", K::view_rows}}},
      {"sensor_noise", reference::sensor_noise, {{"stage_sensor_noise", K::view_rows}}},
      {"display", reference::display, {{"stage_display", K::view_rows}}, true},
      // The physics model's MMW camera.
      {"radiometry", reference::radiometry, {{"stage_radiometry", K::view_rows}}},
      {"optics", reference::optics, {{"stage_optics_rows", K::view_rows}, {"stage_optics_columns", K::view_rows}}},
      {"sample", reference::sample, {{"stage_sample", K::raw_rows}}},
      {"netd", reference::netd, {{"stage_netd", K::raw_rows}}},
      {"window", reference::window, {{"stage_window", K::scenarios}}},
      {"mmw_display", reference::mmw_display, {{"stage_mmw_display", K::scenarios}}, true},
      // The physics model's IR camera. Heat spreading is the PSF's separable Gaussian
      // kernels over the taps its launch passes.
      {"contact_shadow", reference::contact_shadow, {{"stage_contact_shadow", K::view_rows}}},
      {"heat_spread",
       reference::heat_spread,
       {{"stage_optics_rows", K::view_rows}, {"stage_optics_columns", K::view_rows}}},
      {"ir_surface", reference::ir_surface, {{"stage_ir_surface", K::view_rows}}},
      {"ir_netd", reference::ir_netd, {{"stage_ir_netd", K::scenarios}}},
      {"ir_display", reference::ir_display, {{"stage_ir_display", K::scenarios}}, true},
  };
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
