#include "cli/validate_stats.h"

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace portalsim::cli {

namespace {

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); }

double sum_squares(const std::vector<double>& v, double m) {
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return s;
}

// Two-tailed P of t with df degrees of freedom; a zero spread gives t = 0/0 (P = 1: no
// difference) or +-inf (P = 0).
TTest finish(double diff, double se, double df) {
  TTest r;
  r.df = df;
  if (se == 0) {
    r.t = diff == 0 ? 0 : std::copysign(INFINITY, diff);
    r.p = diff == 0 ? 1 : 0;
    return r;
  }
  r.t = diff / se;
  const boost::math::students_t dist(df);
  r.p = 2 * boost::math::cdf(boost::math::complement(dist, std::fabs(r.t)));
  return r;
}

}  // namespace

TTest student_two_sample(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() < 2 || b.size() < 2) throw std::invalid_argument("t-test: each sample needs two values");
  const double ma = mean(a), mb = mean(b);
  const double df = static_cast<double>(a.size() + b.size() - 2);
  const double pooled = (sum_squares(a, ma) + sum_squares(b, mb)) / df;
  return finish(ma - mb, std::sqrt(pooled * (1.0 / a.size() + 1.0 / b.size())), df);
}

TTest corrected_resampled(const std::vector<double>& d, double test_train_ratio) {
  if (d.size() < 2) throw std::invalid_argument("corrected t-test: needs two differences");
  const double m = mean(d);
  const double var = sum_squares(d, m) / (d.size() - 1);
  return finish(m, std::sqrt((1.0 / d.size() + test_train_ratio) * var), static_cast<double>(d.size() - 1));
}

namespace {
constexpr double kZ95 = 1.959963984540054;  // the normal's 97.5% point
}

Interval wilson(long correct, long n) {
  if (n <= 0) throw std::invalid_argument("wilson: no trials");
  const double p = double(correct) / n, z2 = kZ95 * kZ95, d = 1 + z2 / n;
  const double centre = (p + z2 / (2.0 * n)) / d;
  const double half = kZ95 / d * std::sqrt(p * (1 - p) / n + z2 / (4.0 * n * n));
  return {centre - half, centre + half};
}

Interval newcombe_difference(long a, long na, long b, long nb) {
  const Interval ia = wilson(a, na), ib = wilson(b, nb);
  const double pa = double(a) / na, pb = double(b) / nb, d = pa - pb;
  return {d - std::sqrt((pa - ia.lo) * (pa - ia.lo) + (ib.hi - pb) * (ib.hi - pb)),
          d + std::sqrt((ia.hi - pa) * (ia.hi - pa) + (pb - ib.lo) * (pb - ib.lo))};
}

}  // namespace portalsim::cli
