// The physics model's parameters for a view's launch (kernels/contract.h: its camera kind's
// scalars, PsPhysMmw or PsPhysIr, then the tails and tables), with the MMW raw-grid path's
// tables; view_derive.h keeps them per (plan, view). The same formulas
// as the reference's, written again here: the two never share code.
#pragma once
#include <cstdint>
#include <vector>

#include "assets/assets.h"
#include "backend/opencl/display_tables.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim::opencl {

// The physics parameters and tables of view `view`, its knobs `m` (ModelSettings::for_view)
// under `plan`: the values, and where each table starts in them (PsViewLaunch's tables).
struct PhysicsTables {
  std::vector<double> values;
  PsPhysTables at{};
};
PhysicsTables physics_tables(const Catalogue& cat, const AssetSet& assets, const Plan& plan, const ModelSettings& m,
                             int view);
// Parameters that hold `m`'s drawn ranges alone (PsPhys::drawn; the kinds' scalars zero): the
// thesis model's view parameters (kernels/lib/gauss.cl, pixel_sigma_of), and the run's for the
// kernels of no view (metal_zones, metal_physics, analytic_noise).
std::vector<double> drawn_params(const ModelSettings& m);
// Whether `kind`'s CameraKind::physics_fill names one of the fill steps physics_tables knows.
bool has_physics_fill(const CameraKind& kind);

// stage_mmw_display's scratch values per scenario: each view row's vertically
// interpolated raw row, then 16 values per raw row for the pixels after the last run of 16.
size_t mmw_display_scratch(const Sensor& s, int raw_width, int raw_height);

}  // namespace portalsim::opencl
