// Features-only runs of the physics model straight from the MMW raw grid (issue 8 E).
// Everything between the raw grid and a block or region mean is linear: the display
// stage's bilinear interpolation to the view's pixels, the display window and the mean.
// So each feature is a weighted sum of raw cells, tabulated here once per (view, raw
// grid, block size). What this leaves out of the dense path: each pixel's rounding to a
// gray level, and its clamping to 0..255 (the mean is clamped instead). Rounding moves a
// mean by well under a level; clamping matters where the window cuts pixels off, as it
// does the room behind the body under sensor noise (the README gives the measured error).
// The raw grid itself, noise included, is the dense path's to the bit (the same
// physics_raw).
#pragma once
#include <cstdint>
#include <vector>

#include "plan/plan.h"
#include "scene/sensor.h"

namespace portalsim {

struct RawGridPooling {
  std::vector<int32_t> first;    // per feature, then one past the last: its taps [first[f], first[f + 1])
  std::vector<int32_t> cells;    // each tap's raw cell, row * raw_width + column
  std::vector<double> weights;   // each tap's weight; a feature's weights sum to 1
  std::vector<int32_t> columns;  // each feature's column in the feature row
};

// The block means of pooled view `slot` (the view's Sensor `s`) and the means of the
// regions it sees, on a raw grid of raw_width x raw_height cells.
RawGridPooling raw_grid_pooling(const Sensor& s, const FeatureLayout& lay, int slot, int raw_width, int raw_height);

}  // namespace portalsim
