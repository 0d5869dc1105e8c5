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
  const char* name() const override { return "ir_fused"; }
  const std::vector<std::string>& chain() const override {
    static const std::vector<std::string> stages = {"contact_shadow", "heat_spread", "ir_surface"};
    return stages;
  }
  bool applies(const Plan& plan, const Sensor& sensor) const override {
    const std::vector<std::string>& c = sensor.chain_for(plan.model.model);
    return plan.fidelity.fused && c.size() > chain().size() && std::equal(chain().begin(), chain().end(), c.begin());
  }
  bool uses_field() const override { return true; }
  void render(ViewLaunch& v) const override {
    std::vector<std::string> rest(v.chain.begin() + static_cast<std::ptrdiff_t>(chain().size()), v.chain.end());
    if (v.plan.model.ir_netd == 0) std::erase(rest, "ir_netd");
    if (rest == std::vector<std::string>{"ir_display"}) return v.run("ir_surface_display_fused", v.batch.n);
    if (rest == std::vector<std::string>{"ir_netd", "ir_display"})
      return v.run("ir_surface_noise_display_fused", v.batch.n);
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
