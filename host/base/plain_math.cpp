#include "base/plain_math.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace portalsim::plain {
namespace {

// An unevaluated sum hi + lo with |lo| <= ulp(hi) / 2: about 106 bits.
struct DD {
  double hi, lo;
};

constexpr DD two_sum(double a, double b) {
  const double s = a + b, bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}
constexpr DD fast_two_sum(double a, double b) {  // |a| >= |b|
  const double s = a + b;
  return {s, b - (s - a)};
}
// Veltkamp's split and Dekker's exact product, without fma (which a build may or may not
// contract into; the sources are compiled with -ffp-contract=off).
constexpr DD split(double a) {
  const double t = 134217729.0 * a, hi = t - (t - a);
  return {hi, a - hi};
}
constexpr DD two_prod(double a, double b) {
  const double p = a * b;
  const DD x = split(a), y = split(b);
  return {p, ((x.hi * y.hi - p) + x.hi * y.lo + x.lo * y.hi) + x.lo * y.lo};
}
constexpr DD add(DD a, DD b) {
  const DD s = two_sum(a.hi, b.hi);
  return fast_two_sum(s.hi, s.lo + a.lo + b.lo);
}
constexpr DD mul(DD a, DD b) {
  const DD p = two_prod(a.hi, b.hi);
  return fast_two_sum(p.hi, p.lo + (a.hi * b.lo + a.lo * b.hi));
}
constexpr DD div(DD a, DD b) {
  const double q = a.hi / b.hi;
  const DD r = add(a, mul({-q, 0.0}, b));
  return fast_two_sum(q, (r.hi + r.lo) / b.hi);
}

// pi / 2 in three doubles (159 bits), ln 2 and ln 10 in two.
constexpr double kHalfPi1 = 0x1.921fb54442d18p+0, kHalfPi2 = 0x1.1a62633145c07p-54, kHalfPi3 = -0x1.f1976b7ed8fbcp-110,
                 kTwoOverPi = 0x1.45f306dc9c883p-1;
constexpr DD kLn2{0x1.62e42fefa39efp-1, 0x1.abc9e3b39803fp-56};
constexpr DD kLn10{0x1.26bb1bbb55516p+1, -0x1.f48ad494ea3e9p-53};

// p(t) = sum c[j] t^j by Horner's rule: the terms j >= dd_from in plain doubles (they are
// below 1e-6 of the result, so their rounding is below 1e-22 of it), the rest in DD.
template <int N>
constexpr DD horner(const DD (&c)[N], int dd_from, DD t) {
  double tail = c[N - 1].hi;
  for (int j = N - 2; j >= dd_from; --j) tail = tail * t.hi + c[j].hi;
  DD p{tail, 0.0};
  for (int j = dd_from - 1; j >= 0; --j) p = add(mul(p, t), c[j]);
  return p;
}

// sin and cos of a = i / 32, i = 0 .. 26 (past pi/4), made while compiling from their
// Taylor series in DD (15 terms: 1e-32 on |a| <= 0.82): r = a + b leaves |b| <= 1/64,
// whose sine and cosine past b and -b^2 / 2 take four terms in plain doubles (twice as fast
// as the series on r itself; a result of 1/64 or more after cancelling, so 2e-20 relative).
constexpr int kSteps = 32, kTableSize = 27, kTrigTerms = 15;
constexpr auto kTable = [] {
  DD sin_c[kTrigTerms]{}, cos_c[kTrigTerms]{};  // (-1)^j / (2j+1)!, (-1)^j / (2j)!
  DD f{1.0, 0.0};                               // 1 / n!
  for (int n = 0; n < 2 * kTrigTerms; ++n) {
    if (n > 0) f = div(f, {static_cast<double>(n), 0.0});
    (n % 2 ? sin_c : cos_c)[n / 2] = (n / 2) % 2 ? DD{-f.hi, -f.lo} : f;
  }
  struct T {
    DD sin[kTableSize], cos[kTableSize];
  } t{};
  for (int i = 0; i < kTableSize; ++i) {
    const DD a{static_cast<double>(i) / kSteps, 0.0}, a2 = mul(a, a);
    t.sin[i] = mul(a, horner(sin_c, kTrigTerms, a2));
    t.cos[i] = horner(cos_c, kTrigTerms, a2);
  }
  return t;
}();

// 1 / (2j + 1) as DD, for atanh on |s| <= 0.172 (22 terms: 1e-32).
constexpr int kAtanhTerms = 22;
constexpr auto kAtanh = [] {
  struct T {
    DD c[kAtanhTerms];
  } t{};
  for (int j = 0; j < kAtanhTerms; ++j) t.c[j] = div({1.0, 0.0}, {2.0 * j + 1.0, 0.0});
  return t;
}();

}  // namespace

double log(double x) {
  if (!(x > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (x == std::numeric_limits<double>::infinity()) return x;
  int e = 0;
  if (x < 0x1p-1022) x *= 0x1p54, e = -54;  // subnormal: make it normal
  const uint64_t bits = std::bit_cast<uint64_t>(x);
  e += static_cast<int>(bits >> 52) - 1023;
  double m = std::bit_cast<double>((bits & ((uint64_t{1} << 52) - 1)) | (uint64_t{1023} << 52));  // [1, 2)
  if (m > 1.4142135623730951) m *= 0.5, ++e;  // [0.707, 1.414]: |s| <= 0.172
  // ln m = 2 atanh(s), s = (m - 1) / (m + 1); m - 1 is exact (Sterbenz), m + 1 held in DD.
  const DD s = div({m - 1.0, 0.0}, two_sum(m, 1.0));
  const DD series = mul(s, horner(kAtanh.c, 3, mul(s, s)));
  const DD ln_m{2.0 * series.hi, 2.0 * series.lo};
  const DD eln2 = add(two_prod(e, kLn2.hi), {e * kLn2.lo, 0.0});
  const DD r = add(eln2, ln_m);
  return r.hi + r.lo;
}

namespace {

// 1 / j! as DD, for exp on |r| <= 0.35 (24 terms: 1e-35).
constexpr int kExpTerms = 24;
constexpr auto kExp = [] {
  struct T {
    DD c[kExpTerms];
  } t{};
  DD f{1.0, 0.0};
  for (int j = 0; j < kExpTerms; ++j) {
    if (j > 0) f = div(f, {static_cast<double>(j), 0.0});
    t.c[j] = f;
  }
  return t;
}();

// 2^k as a double, for -1074 <= k <= 1023.
double two_to(int k) {
  if (k < -1022) return two_to(k + 54) * 0x1p-54;
  return std::bit_cast<double>(static_cast<uint64_t>(k + 1023) << 52);
}

// e^x of x given in DD: x = k ln 2 + r with |r| <= ln 2 / 2 (k ln 2 exact in DD), e^r by its
// series in DD, then 2^k, in two steps where the result is subnormal (rounded there twice:
// no caller goes near it).
double exp_dd(DD x) {
  if (std::isnan(x.hi)) return x.hi;
  if (x.hi > 709.8) return std::numeric_limits<double>::infinity();
  if (x.hi < -745.2) return 0.0;
  constexpr double kRound = 0x1.8p52;
  const double k = (x.hi * (1.0 / kLn2.hi) + kRound) - kRound;
  DD r = add(x, two_prod(-k, kLn2.hi));
  r = add(r, {-k * kLn2.lo, 0.0});
  const DD e = horner(kExp.c, 8, r);
  const int ki = static_cast<int>(k);
  if (ki < -1021) return (e.hi + e.lo) * two_to(ki + 64) * 0x1p-64;
  if (ki > 1023) return (e.hi + e.lo) * two_to(ki - 1) * 2.0;
  return (e.hi + e.lo) * two_to(ki);
}

}  // namespace

double exp(double x) { return exp_dd({x, 0.0}); }

double exp10(double x) {
  if (std::isnan(x)) return x;
  if (std::abs(x) > 400.0) return x > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return exp_dd(mul({x, 0.0}, kLn10));
}

namespace {

// x = k pi/2 + r with |r| <= pi/4 (a hair more where k rounds), r in DD: each k * part of
// pi/2 is exact as a DD, k < 2^20. Then sin x and cos x are +-sin r or +-cos r by k mod 4,
// and r = +-(a + b) with a = i / 32 from the table: sin r = +-(S + S (cos b - 1) + C sin b),
// cos r = C + C (cos b - 1) - S sin b, in DD.
struct Reduced {
  int quadrant;
  bool negative;                  // r < 0: sin r = -sin |r|
  DD s, c, sin_b, cos_b_minus_1;  // S, C of the table's a; b's
};
Reduced reduce(double x) {
  constexpr double kRound = 0x1.8p52;  // adding and taking it away rounds to an integer
  const double k = (x * kTwoOverPi + kRound) - kRound;
  DD r = add({x, 0.0}, two_prod(-k, kHalfPi1));
  r = add(r, two_prod(-k, kHalfPi2));
  r = add(r, {-k * kHalfPi3, 0.0});
  const bool negative = r.hi < 0;
  if (negative) r = {-r.hi, -r.lo};
  const int i = static_cast<int>(r.hi * kSteps + 0.5);
  const DD b = two_sum(r.hi - static_cast<double>(i) / kSteps, r.lo);  // the difference is exact (Sterbenz)
  const double b2 = b.hi * b.hi;
  // -b^3 / 6 on b.hi alone, and its part of b.lo (-b^2 b.lo / 2), which a near-zero sine needs.
  const double sin_tail =
      b.hi * b2 * (-1.0 / 6 + b2 * (1.0 / 120 - b2 * (1.0 / 5040 - b2 * (1.0 / 362880)))) - 0.5 * b2 * b.lo;
  const DD bb = mul(b, b);
  const double cos_tail = b2 * b2 * (1.0 / 24 - b2 * (1.0 / 720 - b2 * (1.0 / 40320)));
  return {static_cast<int>(static_cast<int64_t>(k) & 3),
          negative,
          kTable.sin[i],
          kTable.cos[i],
          fast_two_sum(b.hi, b.lo + sin_tail),
          fast_two_sum(-0.5 * bb.hi, -0.5 * bb.lo + cos_tail)};
}
DD sin_r_dd(const Reduced& q) {
  const DD s = add(q.s, add(mul(q.s, q.cos_b_minus_1), mul(q.c, q.sin_b)));
  return q.negative ? DD{-s.hi, -s.lo} : s;
}
DD cos_r_dd(const Reduced& q) {
  const DD sb = mul(q.s, q.sin_b);
  return add(q.c, add(mul(q.c, q.cos_b_minus_1), {-sb.hi, -sb.lo}));
}
double sin_r(const Reduced& q) {
  const DD s = sin_r_dd(q);
  return s.hi + s.lo;
}
double cos_r(const Reduced& q) {
  const DD c = cos_r_dd(q);
  return c.hi + c.lo;
}
bool in_range(double x) { return std::abs(x) <= 1e6; }  // false for NaN too
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

// Each computes only the series it returns: the folds take a sine per crease and column.
double sin(double x) {
  if (!in_range(x)) return kNaN;
  const Reduced q = reduce(x);
  const double v = q.quadrant % 2 ? cos_r(q) : sin_r(q);
  return q.quadrant >= 2 ? -v : v;
}

double cos(double x) {
  if (!in_range(x)) return kNaN;
  const Reduced q = reduce(x);
  const double v = q.quadrant % 2 ? sin_r(q) : cos_r(q);
  return q.quadrant == 1 || q.quadrant == 2 ? -v : v;
}

SinCos sincos(double x) {
  if (!in_range(x)) return {kNaN, kNaN};
  const Reduced q = reduce(x);
  const double sn = sin_r(q), cs = cos_r(q);
  switch (q.quadrant) {
    case 0:
      return {sn, cs};
    case 1:
      return {cs, -sn};
    case 2:
      return {-sn, -cs};
    default:
      return {-cs, sn};
  }
}

// sin r / cos r in DD, rounded once; tan x = tan r for even k, -1 / tan r for odd.
double tan(double x) {
  if (!in_range(x)) return kNaN;
  const Reduced q = reduce(x);
  const DD s = sin_r_dd(q), c = cos_r_dd(q);
  const DD t = q.quadrant % 2 ? div({-c.hi, -c.lo}, s) : div(s, c);
  return t.hi + t.lo;
}

}  // namespace portalsim::plain
