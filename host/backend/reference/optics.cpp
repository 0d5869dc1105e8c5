#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

// The Airy pattern's core is 1.02 lambda / D wide at half maximum (radians). The view spans
// fov_rad at range_m: 2 R tan(fov / 2) metres over its width in pixels.
double psf_fwhm_pixels(const Catalogue& cat, const Sensor& view) {
  const PhysicsConfig& pc = cat.physics;
  const double lambda = 299792458.0 / (pc.frequency_ghz * 1e9);
  const double fwhm_m = 1.02 * lambda / pc.aperture_m * pc.range_m;
  const double pixel_m = 2.0 * pc.range_m * std::tan(pc.fov_rad / 2.0) / view.width;
  return fwhm_m / pixel_m;
}

// A Gaussian of standard deviation `sigma` pixels, truncated at 4 sigma and normalised,
// along x then along y; pixels past the edge repeat the edge pixel. sigma 0 changes nothing.
void gaussian_blur(Field& f, double sigma) {
  if (sigma <= 0) return;
  const int R = static_cast<int>(std::ceil(4.0 * sigma));
  std::vector<double> taps(2 * R + 1);
  double total = 0;
  for (int d = -R; d <= R; ++d) total += taps[d + R] = std::exp(-0.5 * d * d / (sigma * sigma));
  for (double& t : taps) t /= total;
  const int W = f.width, H = f.height;
  Field rows = f;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double acc = 0;
      for (int d = -R; d <= R; ++d) acc += taps[d + R] * f.at(std::clamp(x + d, 0, W - 1), y);
      rows.at(x, y) = acc;
    }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double acc = 0;
      for (int d = -R; d <= R; ++d) acc += taps[d + R] * rows.at(x, std::clamp(y + d, 0, H - 1));
      f.at(x, y) = acc;
    }
}

// A Gaussian of the Airy core's FWHM.
void optics(const ViewScene& vs, Field& f) {
  gaussian_blur(f, psf_fwhm_pixels(vs.cat, vs.sensor) / (2.0 * std::sqrt(2.0 * std::log(2.0))));
}

// The IR view is as wide as an MMW view: 2 R tan(fov / 2) metres over its width.
double ir_spread_pixels(const Catalogue& cat, const Sensor& view) {
  const PhysicsConfig& pc = cat.physics;
  const double pixel_mm = 1000.0 * 2.0 * pc.range_m * std::tan(pc.fov_rad / 2.0) / view.width;
  return pc.ir_spread_mm / pixel_mm;
}

// Heat spreading sideways in the fabric: a Gaussian of ir_spread_mm over the shadow field.
void heat_spread(const ViewScene& vs, Field& f) { gaussian_blur(f, ir_spread_pixels(vs.cat, vs.sensor)); }

}  // namespace portalsim::reference
