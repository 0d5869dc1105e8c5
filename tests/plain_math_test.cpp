// base/plain_math.h against values computed to 300 bits (mpmath) and rounded to the
// nearest double: each must come out exactly, argument reduction near multiples of pi/2
// included.
#include "base/plain_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace portalsim::plain {
namespace {

struct LogCase {
  double x, ln;
};
constexpr LogCase kLogs[] = {
    {0x1.0000000000000p-1, -0x1.62e42fefa39efp-1},    {0x1.0000000000000p+0, 0x0.0p+0},
    {0x1.0000000000000p+1, 0x1.62e42fefa39efp-1},     {0x1.4000000000000p+3, 0x1.26bb1bbb55516p+1},
    {0x1.999999999999ap-4, -0x1.26bb1bbb55515p+1},    {0x1.56e1fc2f8f359p-997, -0x1.5963447f87fb5p+9},
    {0x0.0000000000001p-1022, -0x1.74385446d71c3p+9}, {0x1.fffffffffffffp+1023, 0x1.62e42fefa39efp+9},
    {0x1.fffffe0000000p-1, -0x1.0000008000005p-24},   {0x1.6a09e667f3bcdp-1, -0x1.62e42fefa39eep-2},
    {0x1.6a09e667f3bcdp+0, 0x1.62e42fefa39f0p-2},     {0x1.8000000000000p+1, 0x1.193ea7aad030bp+0},
    {0x1.e240c9fbe76c9p+16, 0x1.77281cad8a844p+3},
};

struct TrigCase {
  double x, sin, cos;
};
constexpr TrigCase kTrig[] = {
    {0x1.5798ee2308c3ap-27, 0x1.5798ee2308c3ap-27, 0x1.0000000000000p+0},   // 1e-8
    {0x1.0000000000000p-1, 0x1.eaee8744b05f0p-2, 0x1.c1528065b7d50p-1},     // 0.5
    {0x1.0000000000000p+0, 0x1.aed548f090ceep-1, 0x1.14a280fb5068cp-1},     // 1
    {0x1.0000000000000p+1, 0x1.d18f6ead1b446p-1, -0x1.aa22657537205p-2},    // 2
    {0x1.8000000000000p+1, 0x1.210386db6d55bp-3, -0x1.fae04be85e5d2p-1},    // 3
    {0x1.921fb54442d18p-1, 0x1.6a09e667f3bccp-1, 0x1.6a09e667f3bcdp-1},     // pi/4
    {0x1.921fb54442d18p+0, 0x1.0000000000000p+0, 0x1.1a62633145c07p-54},    // pi/2
    {0x1.921fb54442d18p+1, 0x1.1a62633145c07p-53, -0x1.0000000000000p+0},   // pi
    {0x1.2d97c7f3321d2p+2, -0x1.0000000000000p+0, -0x1.a79394c9e8a0ap-53},  // 3 pi/2
    {0x1.921fb54442d18p+2, -0x1.1a62633145c07p-52, 0x1.0000000000000p+0},   // 2 pi
    {-0x1.4000000000000p+1, -0x1.326af0dcfcab1p-1, -0x1.9a2f7ef858b7dp-1},  // -2.5
    {0x1.4000000000000p+3, -0x1.1689ef5f34f52p-1, -0x1.ad9ac890c6b1fp-1},   // 10
    {0x1.9000000000000p+6, -0x1.03425b78c4db8p-1, 0x1.b981dbf665fdfp-1},    // 100
    {0x1.f400000000000p+9, 0x1.a75cc150a206bp-1, 0x1.1ff026793f1bbp-1},     // 1000
    {0x1.e240c9fbe76c9p+16, -0x1.ff50e60ab53f9p-1, 0x1.a74d27c41b22ap-5},   // 123456.789
    {0x1.4f1a6c638d03fp+0, 0x1.ee8dd4748bf15p-1, 0x1.0907dc1930690p-2},     // 75 degrees
    {0x1.657184ae74487p+1, 0x1.5e3a8748a0bf8p-2, -0x1.e11f642522d1bp-1},    // 160 degrees
};

TEST(PlainMath, LogIsCorrectlyRoundedAtKnownValues) {
  for (const LogCase& c : kLogs) EXPECT_EQ(log(c.x), c.ln) << std::hexfloat << c.x;
  EXPECT_TRUE(std::isnan(log(0.0)));
  EXPECT_TRUE(std::isnan(log(-1.0)));
  EXPECT_EQ(log(std::numeric_limits<double>::infinity()), std::numeric_limits<double>::infinity());
}

TEST(PlainMath, SinAndCosAreCorrectlyRoundedAtKnownValues) {
  for (const TrigCase& c : kTrig) {
    EXPECT_EQ(sin(c.x), c.sin) << std::hexfloat << c.x;
    EXPECT_EQ(cos(c.x), c.cos) << std::hexfloat << c.x;
  }
  EXPECT_TRUE(std::isnan(sin(2e6)));
}

// Between the known values: odd and even symmetry, and sin^2 + cos^2 = 1 to an ulp or two,
// over the range the folds' phases reach.
TEST(PlainMath, SinAndCosAgreeWithEachOther) {
  for (double x = -60.0; x <= 60.0; x += 0.01234567) {
    const SinCos p = sincos(x), m = sincos(-x);
    EXPECT_EQ(m.sin, -p.sin) << x;
    EXPECT_EQ(m.cos, p.cos) << x;
    EXPECT_NEAR(p.sin * p.sin + p.cos * p.cos, 1.0, 4e-16) << x;
  }
}

}  // namespace
}  // namespace portalsim::plain
