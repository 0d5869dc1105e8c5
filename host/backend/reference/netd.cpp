#include <array>
#include <cmath>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

namespace {

// The standard normal quantile Phi^-1(q), q in (0, 1): Acklam's rational approximation
// (relative error < 1.2e-9), then one Halley step on erfc to double precision.
double normal_quantile(double q) {
  static constexpr std::array<double, 6> a = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                                              1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr std::array<double, 5> b = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                              6.680131188771972e+01, -1.328068155288572e+01};
  static constexpr std::array<double, 6> c = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                              -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr std::array<double, 4> d = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                              3.754408661907416e+00};
  double x;
  if (q < 0.02425 || q > 1 - 0.02425) {
    const double t = std::sqrt(-2 * std::log(q < 0.5 ? q : 1 - q));
    x = (((((c[0] * t + c[1]) * t + c[2]) * t + c[3]) * t + c[4]) * t + c[5]) /
        ((((d[0] * t + d[1]) * t + d[2]) * t + d[3]) * t + 1);
    if (q > 0.5) x = -x;
  } else {
    const double u = q - 0.5, r = u * u;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * u /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - q;
  const double step = e * std::sqrt(2 * M_PI) * std::exp(x * x / 2);
  return x - step / (1 + x * step / 2);
}

// Gaussian noise of `sd` kelvin rms on each value of f: cell p's table Gaussian of the
// counter generator's `stream` (kernels/shared.h, PS_GAUSS_ELEMENT): the top PS_GAUSS_BITS
// of a 16-bit half of a draw's word as k, then Phi^-1((k + 1/2) / PS_GAUSS_TABLE), times sd.
void add_noise(const ViewScene& vs, Field& f, double sd, uint32_t stream) {
  if (sd <= 0) return;
  for (int p = 0; p < f.width * f.height; ++p) {
    const Philox4 q = draw(vs.model.seed, vs.index, stream, PS_GAUSS_ELEMENT(vs.view, p));
    const uint32_t k = PS_GAUSS_INDEX(q[PS_GAUSS_WORD(p)], p);
    f.v[p] += sd * normal_quantile((k + 0.5) / PS_GAUSS_TABLE);
  }
}

}  // namespace

// The MMW camera's NETD, per raw pixel, integrated over `frames` raw frames: the scene holds
// still while the camera averages them, so each frame adds its own draw of NETD / frames
// (frame 0 from the raw-noise stream, frame k from PS_STREAM_FRAME_NOISE + k).
void netd(const ViewScene& vs, Field& f) {
  const int n = vs.model.frames;
  for (int k = 0; k < n; ++k)
    add_noise(vs, f, vs.model.netd / n, k == 0 ? kStreamRawNoise : PS_STREAM_FRAME_NOISE + uint32_t(k));
}

// The IR camera's NETD, per view pixel.
void ir_netd(const ViewScene& vs, Field& f) { add_noise(vs, f, vs.model.ir_netd, kStreamIrNoise); }

}  // namespace portalsim::reference
