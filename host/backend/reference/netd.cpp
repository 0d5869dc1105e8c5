#include <cmath>
#include <numbers>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

namespace {
// Gaussian noise of `sd` kelvin rms on each value of f: Box-Muller over the counter
// generator's `stream`, one draw per value pair (2k, 2k+1), as sensor_noise draws per pixel.
void add_noise(const ViewScene& vs, Field& f, double sd, uint32_t stream) {
  if (sd <= 0) return;
  for (int p = 0; p < f.width * f.height; ++p) {
    const uint32_t element =
        (static_cast<uint32_t>(vs.view) << PS_PIXEL_NOISE_VIEW_SHIFT) | static_cast<uint32_t>(p / 2);
    const Philox4 q = draw(vs.model.seed, vs.index, stream, element);
    const double u1 = 1.0 - uniform24(q[0]), u2 = uniform24(q[1]);
    const double rad = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    f.v[p] += sd * (p % 2 == 0 ? rad * std::cos(angle) : rad * std::sin(angle));
  }
}
}  // namespace

// The MMW camera's NETD, per raw pixel.
void netd(const ViewScene& vs, Field& f) { add_noise(vs, f, vs.model.netd, kStreamRawNoise); }

// The IR camera's NETD, per view pixel.
void ir_netd(const ViewScene& vs, Field& f) { add_noise(vs, f, vs.model.ir_netd, kStreamIrNoise); }

}  // namespace portalsim::reference
