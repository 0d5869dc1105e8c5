#include <cmath>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

namespace {
constexpr double kTwoPi = 6.283185307179586;
}

// Per-pixel Gaussian sensor noise, sigma gray levels: Box-Muller over the counter
// generator, one draw per pixel pair (2k, 2k+1) of the view.
void sensor_noise(const ViewScene& vs, Field& f) {
  const double sigma = vs.model.pixel_sigma;
  if (sigma <= 0) return;
  const int pixels = f.width * f.height;
  for (int p = 0; p < pixels; ++p) {
    const uint32_t element =
        (static_cast<uint32_t>(vs.view) << PS_PIXEL_NOISE_VIEW_SHIFT) | static_cast<uint32_t>(p / 2);
    const Philox4 r = draw(vs.model.seed, vs.index, kStreamPixelNoise, element);
    const double u1 = 1.0 - uniform24(r[0]), u2 = uniform24(r[1]);
    const double rad = std::sqrt(-2.0 * std::log(u1));
    const double g = (p % 2 == 0) ? rad * std::cos(kTwoPi * u2) : rad * std::sin(kTwoPi * u2);
    f.v[p] += sigma * g;
  }
}

}  // namespace portalsim::reference
