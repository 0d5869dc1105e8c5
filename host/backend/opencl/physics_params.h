// The physics model's parameters for a view's launch (kernels/shared.h, PS_PHYS_*), at the
// kernels' parameter precision, with the MMW raw-grid path's tables. The same formulas as
// the reference's, written again here: the two never share code. Kept per (view, knobs,
// precision): the bare raw grids cost a few milliseconds.
#pragma once
#include <CL/opencl.hpp>
#include <map>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/opencl/buffers.h"
#include "backend/opencl/display_tables.h"
#include "base/lru_cache.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim::opencl {

class PhysicsParams {
 public:
  PhysicsParams(const Catalogue& cat, const AssetSet& assets, cl::Context& ctx)
      : cat_(cat), assets_(assets), ctx_(ctx) {}
  // The parameters of `view` under `plan`; fills L's offsets into them (all 0, and a
  // placeholder buffer, under the thesis model).
  cl::Buffer operator()(bool fp64, const Plan& plan, int view, PsViewLaunch& L);

  struct Tables {
    std::vector<double> values;
    int32_t radius = 0, wx = 0, wy = 0, cband = 0, rband = 0, base = 0, gauss = 0, off_body = 0;
    DisplayTables display;  // stage_mmw_display's (MMW views)
    cl::Buffer buffer;
  };

 private:
  Tables make(const Plan& plan, const Sensor& s, int view) const;

  const Catalogue& cat_;
  const AssetSet& assets_;
  cl::Context& ctx_;
  // Per (knobs, view, precision); a run uses one per view and precision.
  LruCache<std::string, Tables> tables_{32};
  Grown none_;
};

// stage_mmw_display's scratch values per scenario: each view row's vertically
// interpolated raw row, then 16 values per raw row for the pixels after the last run of 16.
size_t mmw_display_scratch(const Sensor& s, int raw_width, int raw_height);

}  // namespace portalsim::opencl
