#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

namespace {
// Where view pixel x's centre falls on a raw axis of `raw` pixels (raw centres at whole
// numbers), held to the outermost centres.
double raw_coordinate(int x, int size, int raw) { return std::clamp((x + 0.5) * raw / size - 0.5, 0.0, raw - 1.0); }

// Kelvin t through the window [lo, hi] to a level 0..255, rounded half up and clamped.
double window_level(double t, double lo, double hi) {
  return std::clamp(std::floor((t - lo) / (hi - lo) * 255.0 + 0.5), 0.0, 255.0);
}
}  // namespace

// The raw grid, interpolated bilinearly to the view's size, then the display window
// [display_min, display_max] kelvin to gray 0..255, rounded half up and clamped.
void mmw_display(const ViewScene& vs, Field& f) {
  const PhysicsConfig& pc = vs.cat.physics;
  const int W = vs.sensor.width, H = vs.sensor.height, RW = f.width, RH = f.height;
  Field out;
  out.width = W;
  out.height = H;
  out.v.assign(static_cast<size_t>(W) * H, 0.0);
  for (int y = 0; y < H; ++y) {
    const double v = raw_coordinate(y, H, RH);
    const int r0 = static_cast<int>(std::floor(v)), r1 = std::min(r0 + 1, RH - 1);
    const double ty = v - r0;
    for (int x = 0; x < W; ++x) {
      const double u = raw_coordinate(x, W, RW);
      const int c0 = static_cast<int>(std::floor(u)), c1 = std::min(c0 + 1, RW - 1);
      const double tx = u - c0;
      const double t =
          (1 - ty) * ((1 - tx) * f.at(c0, r0) + tx * f.at(c1, r0)) + ty * ((1 - tx) * f.at(c0, r1) + tx * f.at(c1, r1));
      out.at(x, y) = window_level(t, pc.display_min, pc.display_max);
    }
  }
  f = std::move(out);
}

// The IR camera: its window [ir_display_min, ir_display_max] kelvin to the temperature
// index 0..255 (then through the palette), at the view's own pixels.
void ir_display(const ViewScene& vs, Field& f) {
  const PhysicsConfig& pc = vs.cat.physics;
  for (double& t : f.v) t = window_level(t, pc.ir_display_min, pc.ir_display_max);
}

}  // namespace portalsim::reference
