// One camera view's launch for a batch: the settings (PsViewLaunch) and buffers that every
// kernel of VIEW_STAGE_ARGS (kernels/composite.cl) takes, whichever path renders the view.
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "backend/opencl/device.h"
#include "backend/opencl/kernels.h"
#include "backend/opencl/launch.h"
#include "backend/opencl/view_derive.h"
#include "backend/stages.h"
#include "plan/plan.h"

namespace portalsim::opencl {

class ViewLaunch {
 public:
  // View `view` of the batch under `plan`, its pixels into `out`. uses_field: the path's
  // stages pass a field of reals between them (else its kernels write `out` directly);
  // tabulated: place_view skips the scenarios whose features come from tables
  // (PS_FLAG_TABULATED, physics_raw_features); noise_free: the MMW raw grid without its NETD
  // (physics_raw_features draws it per feature).
  ViewLaunch(Device& d, Kernels& K, const Plan& plan, int view, const DeviceBatch& batch, const cl::Buffer& out,
             bool uses_field, bool tabulated = false, bool noise_free = false);
  // Queues the kernel called `kernel` over `items` work-items.
  void run(std::string_view kernel, size_t items);
  // Queues a stage's kernel: a work-item per scenario, or per (scenario, row) it covers.
  void run(const StageKernel& k);

  const Plan& plan;
  const Sensor& sensor;
  const std::vector<std::string>& chain;  // the view's stages under the plan's model
  const DeviceBatch& batch;
  const std::shared_ptr<ViewDerived> derived;  // what the view's kernels read (view_derive.h)
  const ViewStageArgs& args() const { return args_; }

 private:
  Kernels& K_;
  Device& d_;
  ViewStageArgs args_;
};

}  // namespace portalsim::opencl
