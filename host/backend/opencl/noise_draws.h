// The unit draws of a sensor model's per-pixel noise as a fidelity variant's kernels make
// them (kernels/noise_draws.cl), for `portalsim tradeoff`'s distribution
// columns: the thesis model's pixel noise (the variant's noise_draw), the physics model's
// MMW raw noise (table Gaussians, or under irwin-hall the fast tier's draws).
#pragma once
#include <cstdint>
#include <vector>

#include "backend/opencl/kernels.h"

namespace portalsim::opencl {

// Pixels [0, cells) of view 0 of scenarios first .. first + scenarios - 1, scenario by
// scenario; `counts` are the catalogue's (the program is the one its backend builds).
std::vector<double> noise_draws(OpenCLRuntime& rt, const Fidelity& f, KernelCounts counts, Model model, uint64_t seed,
                                uint64_t first, size_t scenarios, int cells);

}  // namespace portalsim::opencl
