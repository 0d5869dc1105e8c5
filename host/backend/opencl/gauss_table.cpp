#include "backend/opencl/gauss_table.h"

#include <cmath>

#include "shared.h"

namespace portalsim {

namespace {

// Phi^-1(q) for q in (0, 1/2]: Abramowitz and Stegun 26.2.23 (error < 4.5e-4) as the start,
// then Newton's method on Phi(x) = erfc(-x / sqrt 2) / 2 to double precision.
double lower_quantile(double q) {
  const double t = std::sqrt(-2.0 * std::log(q));
  double x = -(t - (2.515517 + t * (0.802853 + t * 0.010328)) / (1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308))));
  for (int i = 0; i < 6; ++i) {
    const double density = std::exp(-0.5 * x * x) / std::sqrt(2.0 * M_PI);
    x -= (0.5 * std::erfc(-x / std::sqrt(2.0)) - q) / density;
  }
  return x;
}

}  // namespace

const std::vector<double>& gauss_table() {
  static const std::vector<double> table = [] {
    std::vector<double> t(PS_GAUSS_TABLE);
    for (int k = 0; k < PS_GAUSS_TABLE / 2; ++k) {
      const double x = lower_quantile((k + 0.5) / PS_GAUSS_TABLE);
      t[k] = x;
      t[PS_GAUSS_TABLE - 1 - k] = -x;  // the quantile is odd about 1/2
    }
    return t;
  }();
  return table;
}

}  // namespace portalsim
