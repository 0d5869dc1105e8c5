// Features-only runs of the physics model straight from the MMW raw grid (issue 8 E).
// Everything between the raw grid and a block or region mean is linear: the display
// stage's bilinear interpolation to the view's pixels, the display window and the mean.
// So each feature is a weighted sum of raw cells, tabulated here once per (view, raw
// grid, block size). What this leaves out of the dense path: each pixel's rounding to a
// gray level, and its clamping to 0..255 (the mean is clamped instead). Rounding moves a
// mean by well under a level; clamping matters where the window cuts pixels off, as it
// does the room behind the body under sensor noise (docs/model/physics-mmw.md gives the measured error).
// The noise-free raw grid is the dense path's to the bit (the same physics_raw), or, where
// a scenario's objects stand at their places apart from each other, the sum of tabulated
// responses (the subject's bare features plus each object's change, made once by
// physics_raw itself). Sensor noise is drawn in feature space (RawGridNoise): the exact
// joint distribution of the features that per-raw-pixel noise of the NETD gives, not the
// same draws as the dense path.
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

// Unit-variance noise on every raw cell, as the features of one pooled view see it: the
// blocks' covariance is the Kronecker product Gy (x) Gx of the axes' Gram matrices, so the
// block noise is Ly Z Lx^T with Z independent standard normals and Ly, Lx their (banded)
// Cholesky factors; each region's noise is then its regression on Z plus its own part,
// r = B z + Lr z_r (B's rows separable, Lr the Cholesky factor of what is left). Singular
// Gram matrices (more blocks than raw cells along an axis) are factored with a ridge of
// 1e-10 of their scale. Z is laid out by block row, then the regions' own draws.
struct RawGridNoise {
  int blocks_x = 0, blocks_y = 0, band_x = 0, band_y = 0, regions = 0;
  // Per block q = by blocks_x + bx, so that the kernel's loops run over all blocks at once:
  std::vector<double> dx;             // (band_x + 1) x blocks: dx[d blocks + q] = Lx[bx][bx - d]
  std::vector<double> dy;             // (band_y + 1) x blocks: dy[d blocks + q] = Ly[by][by - d]
  std::vector<double> region_blocks;  // regions x (blocks_y blocks_x): B over Z's layout
  std::vector<double> region_own;     // regions x regions, lower triangular: Lr
  // The covariance of features f and g (indices into RawGridPooling's order) that unit
  // raw-cell noise gives through the pooling: the exact value the draws must reproduce.
  static double covariance(const RawGridPooling& p, int f, int g);
};
RawGridNoise raw_grid_noise(const Sensor& s, const FeatureLayout& lay, int raw_width, int raw_height);

}  // namespace portalsim
