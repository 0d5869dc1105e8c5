#include "backend/reference/draws.h"

#include <array>
#include <cmath>

#include "scene/philox.h"

namespace portalsim::reference {

// Acklam's rational approximation (relative error < 1.2e-9), then one Halley step on erfc
// to double precision.
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

// Cells go 128 to a block of 16 draws side by side: cell p is in block p / 128, draw
// p % 16 of it, word (p % 128) / 32, half (p / 16) % 2 (low first).
namespace {
uint32_t cell_half(uint64_t seed, uint64_t index, uint32_t stream, int view, int p) {
  const uint32_t block = static_cast<uint32_t>(p) / 128, in_block = static_cast<uint32_t>(p) % 128;
  const uint32_t element = (static_cast<uint32_t>(view) << PS_PIXEL_NOISE_VIEW_SHIFT) | (16 * block + in_block % 16);
  const uint32_t word = draw(seed, index, stream, element)[in_block / 32];
  return (in_block / 16) % 2 == 0 ? word & 0xffffu : word >> 16;
}
}  // namespace

double table_gaussian(uint64_t seed, uint64_t index, uint32_t stream, int view, int p) {
  const uint32_t k = cell_half(seed, index, stream, view, p) >> (16 - PS_GAUSS_BITS);
  return normal_quantile((k + 0.5) / PS_GAUSS_TABLE);
}

// The cell's half as table_gaussian finds it, its bytes' sum through the quintic.
double fast_gaussian(uint64_t seed, uint64_t index, uint32_t stream, int view, int p) {
  const uint32_t half = cell_half(seed, index, stream, view, p);
  const double t = (static_cast<double>(half & 0xffu) + static_cast<double>(half >> 8) - 255.0) / 255.0;
  return t * (PS_IH_C1 + t * t * (PS_IH_C3 + t * t * PS_IH_C5));
}

double pixel_irwin_hall(uint64_t seed, uint64_t index, int view, int p) {
  return fast_gaussian(seed, index, kStreamPixelNoiseFast, view, p);
}

namespace {
// Box-Muller over the first two words of r: u1 = 1 - uniform24(w0) in (0, 1], u2 =
// uniform24(w1); the cosine, or the sine for the pair's second value.
double box_muller(const Philox4& r, bool second) {
  const double u1 = 1.0 - uniform24(r[0]), u2 = uniform24(r[1]);
  const double rad = std::sqrt(-2.0 * std::log(u1));
  constexpr double kTwoPi = 6.283185307179586;
  return second ? rad * std::sin(kTwoPi * u2) : rad * std::cos(kTwoPi * u2);
}
}  // namespace

double pixel_gaussian(uint64_t seed, uint64_t index, int view, int p) {
  const uint32_t element = (static_cast<uint32_t>(view) << PS_PIXEL_NOISE_VIEW_SHIFT) | static_cast<uint32_t>(p / 2);
  return box_muller(draw(seed, index, kStreamPixelNoise, element), p % 2 != 0);
}

double block_mean_gaussian(uint64_t seed, uint64_t index, int q) {
  return box_muller(draw(seed, index, kStreamBlockNoise, static_cast<uint32_t>(q - q % 2)), q % 2 != 0);
}

}  // namespace portalsim::reference
