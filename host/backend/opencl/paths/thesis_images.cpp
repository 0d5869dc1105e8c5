// The thesis model's fused view path: render_view (kernels/render.cl) makes a whole view
// per work-item, its composite, pattern noise, sensor noise and display in one pass, with
// the stage kernels' bits.
#include "backend/opencl/paths/paths.h"

namespace portalsim::opencl {

namespace {

class ThesisImages final : public ViewPath {
 public:
  ThesisImages() : ViewPath("thesis_images", {"composite", "pattern_noise", "sensor_noise", "display"}, false) {}
  Gate gate(const Plan& plan, const Sensor& sensor) const override {
    return {.runs = plan.fidelity.fused && sensor.chain_for(plan.model.model) == chain()};
  }
  void render(ViewLaunch& v, const Gate&) const override { v.run("render_view", v.batch.n); }
};

}  // namespace

const ViewPath& thesis_images_path() {
  static const ThesisImages path;
  return path;
}

}  // namespace portalsim::opencl
