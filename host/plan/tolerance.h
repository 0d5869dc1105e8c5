// Each fidelity tier's stated tolerance against the fp64 CPU reference. Tests hold the
// kernels to these (check_tolerance in backend/compare.h); `portalsim tradeoff` reports
// where each tier actually lands.
#pragma once

#include <algorithm>

#include "plan/plan.h"

namespace portalsim {

struct Tolerance {
  int pixel_max_abs;             // gray levels (MMW) and temperature index (IR)
  double pixel_share_differing;  // share of pixels that may differ at all
  double feature_max_abs;        // without the block-mean noise model
  double feature_mean_abs;
  // Metal zones and labels are integers and match exactly in every tier.
};

// A pixel whose exact value is an x.5 tie (at alpha 0.9 over 0 or 255 every opaque
// pixel is one: 0.1 * 255 = 25.5) rounds by the last bit of the arithmetic, so the
// share of pixels that differ by one level depends on the images; the bounds below are
// the worst measured over the default catalogue and tests/extremes_test.cpp's black
// and white images, with margin.
inline Tolerance tier_tolerance(Tier t) {
  switch (t) {
    case Tier::exact:  // fp64, the reference's formulas: ties and libm's last bits
      return {1, 1e-3, 0.05, 1e-3};
    case Tier::standard:                   // fp32: ties, also carried through overlapping blends
      return {1, 0.05, 1.0 + 1e-4, 0.05};  // a mean of pixels within 1, plus its float rounding
    case Tier::fast:                       // 8.8 fixed point: alpha and noise gain quantised to 1/256
      return {2, 0.5, 2.0, 0.5};
  }
  return {0, 0, 0, 0};
}

// The physics model's MMW camera in every tier (tests/physics_test.cpp): pixels within 1
// gray level, at most 0.5% of them off by one, features within 1 and, being means of
// those pixels, on average within 0.005 (plus float rounding). Its other sensors still run
// the thesis's chains, so pixels keep the tier's bounds where those are wider. The fast
// tier's features-only runs take the raw-grid path, which leaves each pixel's rounding
// and clamping out (backend/opencl/raw_grid_pooling.h) and draws the NETD per feature
// (its distribution is tested, not its draws, so these bounds are for NETD 0): where the
// display window clamps a mean may be off by many levels, so only the mean error is
// bounded.
inline Tolerance model_tolerance(Model m, Tier t) {
  const Tolerance thesis = tier_tolerance(t);
  if (m == Model::thesis) return thesis;
  const bool raw_grid = t == Tier::fast;
  return {std::max(1, thesis.pixel_max_abs), std::max(0.005, thesis.pixel_share_differing),
          raw_grid ? 255.0 : 1.0 + 1e-4, raw_grid ? 0.1 : 0.005 + 1e-4};
}

}  // namespace portalsim
