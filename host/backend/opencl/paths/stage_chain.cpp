// The general view path: each stage of the view's chain as its own kernels, in order, over
// a field of reals (backend/stages.h). It renders every chain, and is what the fast paths
// are checked against bit for bit.
#include "backend/opencl/paths/paths.h"

namespace portalsim::opencl {

namespace {

class StageChain final : public ViewPath {
 public:
  StageChain() : ViewPath("stage_chain", {}, true) {}  // no chain of its own: whatever the view's is
  Gate gate(const Plan&, const Sensor&) const override { return {.runs = true}; }
  void render(ViewLaunch& v, const Gate&) const override { run_stages(v, 0); }
};

}  // namespace

void run_stages(ViewLaunch& v, size_t from) {
  for (size_t k = from; k < v.chain.size(); ++k)
    for (const StageKernel& sk : view_stage(v.chain[k]).kernels) v.run(sk);
}

const ViewPath& stage_chain_path() {
  static const StageChain path;
  return path;
}

const std::vector<const ViewPath*>& view_paths() {
#define PORTALSIM_VIEW_PATH_ADDRESS(name) &name##_path(),
  static const std::vector<const ViewPath*> paths = {PORTALSIM_FAST_VIEW_PATHS(PORTALSIM_VIEW_PATH_ADDRESS)};
#undef PORTALSIM_VIEW_PATH_ADDRESS
  return paths;
}

ViewRoute view_route(const Plan& plan, const Sensor& sensor) {
  for (const ViewPath* p : view_paths())
    if (const Gate g = p->gate(plan, sensor); g.runs) return {p, g};
  return {&stage_chain_path(), stage_chain_path().gate(plan, sensor)};
}

std::string describe(const char* path, const Gate& g) {
  return *g.variant_name ? std::string(path) + " (" + g.variant_name + ")" : std::string(path);
}

}  // namespace portalsim::opencl
