// The physics model's IR view path: ir_surface_fused (kernels/ir_surface_fused.cl) does the
// chain's first stages, contact shadow, heat spread and surface, in one pass; the later
// stages run as their kernels, or, where only ir_display is left (ir_netd at 0 K draws
// nothing), ir_surface_display_fused shows the surface itself, and where ir_netd then
// ir_display are left, ir_surface_noise_display_fused draws the noise and shows it too.
#include <algorithm>

#include "backend/opencl/paths/paths.h"

namespace portalsim::opencl {

namespace {

class IrFused final : public ViewPath {
 public:
  IrFused() : ViewPath("ir_fused", {"contact_shadow", "heat_spread", "ir_surface"}, true) {}
  enum Variant { kThenStages, kDisplayFused, kNoiseDisplayFused };
  Gate gate(const Plan& plan, const Sensor& sensor) const override {
    const std::vector<std::string>& c = sensor.chain_for(plan.model.model);
    if (!plan.fidelity.fused || c.size() <= chain().size() || !std::equal(chain().begin(), chain().end(), c.begin()))
      return {};
    // The stages after the fused ones; ir_netd at 0 K draws nothing.
    std::vector<std::string> rest(c.begin() + static_cast<std::ptrdiff_t>(chain().size()), c.end());
    const ModelSettings m = plan.model.for_view(sensor);
    if (m.ir_netd == 0 && !m.drawn[PS_DRAWN_IR_NETD].varies()) std::erase(rest, "ir_netd");
    if (rest == std::vector<std::string>{"ir_display"})
      return {.runs = true, .variant = kDisplayFused, .variant_name = "surface and display fused"};
    if (rest == std::vector<std::string>{"ir_netd", "ir_display"})
      return {.runs = true, .variant = kNoiseDisplayFused, .variant_name = "surface, noise and display fused"};
    return {.runs = true, .variant = kThenStages, .variant_name = "surface fused, then the stage kernels"};
  }
  void render(ViewLaunch& v, const Gate& g) const override {
    if (g.variant == kDisplayFused) return v.run("ir_surface_display_fused", v.batch.n);
    if (g.variant == kNoiseDisplayFused) return v.run("ir_surface_noise_display_fused", v.batch.n);
    v.run("ir_surface_fused", v.batch.n);
    run_stages(v, chain().size());
  }
};

}  // namespace

const ViewPath& ir_fused_path() {
  static const IrFused path;
  return path;
}

}  // namespace portalsim::opencl
