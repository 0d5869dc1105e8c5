// The MMW camera's display as the kernels take it (kernels/mmw_display.cl): the
// interpolation from the raw grid to the view and any smoothing after it, as weight tables
// derived once per launch from the knobs; and the frames as the kernels draw them.
#pragma once
#include <cstdint>
#include <vector>

#include "contract.h"
#include "plan/plan.h"

namespace portalsim::opencl {

// Where the tables lie in the launch's parameters (PsPhysTables::display).
using DisplayTables = PsDisplayTables;

// Appends stage_mmw_display's tables for a W x H view over an RW x RH raw grid to `p`.
DisplayTables append_display_tables(std::vector<double>& p, const ModelSettings& m, int W, int H, int RW, int RH);

// The frames the kernels draw, and the NETD each frame's draw is scaled from: every frame
// with the NETD, or, where the plan approximates them, one frame of NETD / sqrt(frames);
// `m` is the view's knobs (ModelSettings::for_view).
int kernel_frames(const Plan& plan, const ModelSettings& m);
double kernel_netd(const Plan& plan, const ModelSettings& m);

// The MMW noise the kernels draw per scenario (kernels/netd.cl, mmw_noise_of): where
// neither the NETD nor the frames is drawn, netd_lo = netd_hi = kernel_netd and one frame
// count; else the knobs' ranges (drawn_knob_at), as_one under the block-mean model.
struct MmwNoise {
  double netd_lo = 0, netd_hi = 0;
  int frames_lo = 1, frames_hi = 1;
  bool as_one = false;
  bool drawn() const { return netd_hi > netd_lo || frames_hi > frames_lo; }
};
MmwNoise mmw_noise(const Plan& plan, const ModelSettings& m);

}  // namespace portalsim::opencl
