// The physics model's MMW view path: physics_raw (kernels/physics_raw.cl) makes each
// scenario's raw grid straight from the placement records, radiometry, optics, sampling
// and NETD together; stage_window sets the automatic window, or the scenario's drawn one,
// where the plan has it, and stage_mmw_display then shows it.
#include "backend/opencl/paths/paths.h"

namespace portalsim::opencl {

namespace {

class PhysicsRaw final : public ViewPath {
 public:
  PhysicsRaw() : ViewPath("physics_raw", {"radiometry", "optics", "sample", "netd", "window", "mmw_display"}, false) {}
  enum Variant { kFixedWindow, kAutoWindow, kDrawnWindow };
  Gate gate(const Plan& plan, const Sensor& sensor) const override {
    if (!plan.fidelity.fused || sensor.chain_for(plan.model.model) != chain()) return {};
    if (plan.model.window_auto) return {.runs = true, .variant = kAutoWindow, .variant_name = "automatic window"};
    if (plan.model.window_drawn()) return {.runs = true, .variant = kDrawnWindow, .variant_name = "drawn window"};
    return {.runs = true, .variant = kFixedWindow, .variant_name = "fixed window"};
  }
  void render(ViewLaunch& v, const Gate& g) const override {
    run_raw_grid(v);
    if (g.variant != kFixedWindow) v.run("stage_window", v.batch.n);
    v.run("stage_mmw_display", v.batch.n);
  }
};

}  // namespace

void run_raw_grid(ViewLaunch& v) { v.run("physics_raw", v.batch.n); }

const ViewPath& physics_raw_path() {
  static const PhysicsRaw path;
  return path;
}

}  // namespace portalsim::opencl
