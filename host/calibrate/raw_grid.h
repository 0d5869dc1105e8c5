// The MMW camera's raw grid, told from its displayed images: the display interpolates the
// raw grid bilinearly (reference::mmw_display), so every row of a view lies, up to
// rounding, in the span of the interpolation's columns for the true number of raw pixels
// across, and not for fewer. The same holds down the columns.
#pragma once
#include <cstdint>
#include <vector>

namespace portalsim::calibrate {

struct GridAxis {
  int raw = 0;                // raw pixels along the axis: the fewest that fit
  std::vector<double> ms;     // mean square residual (gray^2) for 1 .. size raw pixels
  std::vector<double> bound;  // the most rounding alone leaves, for each
};

// Tells the raw pixels along x (rows) or y (columns) from images of `width` x `height`
// pixels. Pixels at 0 or 255 (clipped by the window) are left out of the fit.
GridAxis raw_grid_axis(const std::vector<const std::vector<uint8_t>*>& images, int width, int height, bool along_x);

// The raw grid (raw_h x raw_w, gray levels before rounding) that `img` interpolates, by
// least squares along x then y; `valid` (per raw cell) is false where the cell reaches a
// clipped pixel.
void recover_raw(const std::vector<uint8_t>& img, int width, int height, int raw_w, int raw_h, std::vector<double>& raw,
                 std::vector<char>& valid);

// The variance a raw cell recovered by recover_raw gets from rounding alone (1/12 gray^2
// per pixel through the least squares), averaged over the cells.
double rounding_variance(int width, int height, int raw_w, int raw_h);

}  // namespace portalsim::calibrate
