// The MMW camera's display as the kernels take it (kernels/mmw_display.cl): the
// interpolation from the raw grid to the view and any smoothing after it, as weight tables
// derived once per launch from the knobs; and the frames as the kernels draw them.
#pragma once
#include <cstdint>
#include <vector>

#include "plan/plan.h"

namespace portalsim::opencl {

// Where the tables lie in the launch's parameters (PsViewLaunch's display fields).
struct DisplayTables {
  int32_t stride = 0, dx = 0, dxband = 0, dy = 0, dyband = 0;
};

// Appends stage_mmw_display's tables for a W x H view over an RW x RH raw grid to `p`.
DisplayTables append_display_tables(std::vector<double>& p, const ModelSettings& m, int W, int H, int RW, int RH);

// The frames the kernels draw, and the NETD each frame's draw is scaled from: every frame
// with the NETD, or, where the plan approximates them, one frame of NETD / sqrt(frames);
// `m` is the view's knobs (ModelSettings::for_view).
int kernel_frames(const Plan& plan, const ModelSettings& m);
double kernel_netd(const Plan& plan, const ModelSettings& m);

}  // namespace portalsim::opencl
