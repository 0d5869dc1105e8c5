#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

namespace {
// Where view pixel x's centre falls on a raw axis of `raw` pixels (raw centres at whole
// numbers), held to the outermost centres.
double raw_coordinate(int x, int size, int raw) { return std::clamp((x + 0.5) * raw / size - 0.5, 0.0, raw - 1.0); }

// Keys' cubic convolution kernel, a = -1/2 (Keys 1981): interpolates, and reproduces
// quadratics.
double keys(double s) {
  s = std::fabs(s);
  if (s <= 1) return (1.5 * s - 2.5) * s * s + 1;
  if (s < 2) return ((-0.5 * s + 2.5) * s - 4) * s + 2;
  return 0;
}

// The raw grid at (u, v), raw cells at whole numbers, cells past an edge repeat the edge.
double interpolate(const Field& f, double u, double v, DisplayFilter filter) {
  const auto cell = [&](int c, int r) { return f.at(std::clamp(c, 0, f.width - 1), std::clamp(r, 0, f.height - 1)); };
  const int c0 = static_cast<int>(std::floor(u)), r0 = static_cast<int>(std::floor(v));
  const double tx = u - c0, ty = v - r0;
  if (filter == DisplayFilter::bilinear)
    return (1 - ty) * ((1 - tx) * cell(c0, r0) + tx * cell(c0 + 1, r0)) +
           ty * ((1 - tx) * cell(c0, r0 + 1) + tx * cell(c0 + 1, r0 + 1));
  double t = 0;
  for (int j = -1; j <= 2; ++j)
    for (int i = -1; i <= 2; ++i) t += keys(j - ty) * keys(i - tx) * cell(c0 + i, r0 + j);
  return t;
}

// Kelvin t through the window [lo, hi] to a level 0..255, rounded half up and clamped.
double window_level(double t, double lo, double hi) {
  return std::clamp(std::floor((t - lo) / (hi - lo) * 255.0 + 0.5), 0.0, 255.0);
}
}  // namespace

// The raw grid interpolated to the view's size (display_filter), smoothed by a Gaussian of
// `smooth` view pixels (edges held), then the fixed window [window_lo, window_hi] kelvin to
// gray 0..255, rounded half up and clamped. (The automatic window is the `window` stage's:
// it has put the raw grid on the fixed window's scale.)
void mmw_display(const ViewScene& vs, Field& f) {
  const ModelSettings& m = vs.model;
  const int W = vs.sensor.width, H = vs.sensor.height, RW = f.width, RH = f.height;
  Field out;
  out.width = W;
  out.height = H;
  out.v.assign(static_cast<size_t>(W) * H, 0.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      out.at(x, y) = interpolate(f, raw_coordinate(x, W, RW), raw_coordinate(y, H, RH), m.display_filter);
  gaussian_blur(out, m.smooth);
  for (double& t : out.v) t = window_level(t, m.window_lo, m.window_hi);
  f = std::move(out);
}

// The IR camera: its window [ir_display_min, ir_display_max] kelvin to the temperature
// index 0..255 (then through the palette), at the view's own pixels.
void ir_display(const ViewScene& vs, Field& f) {
  const PhysicsConfig& pc = vs.cat.physics;
  for (double& t : f.v) t = window_level(t, pc.ir_display_min, pc.ir_display_max);
}

}  // namespace portalsim::reference
