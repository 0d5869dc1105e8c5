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

struct Case {
  double x, y;
};
constexpr Case kExps[] = {
    {0x0.0p+0, 0x1.0000000000000p+0},
    {0x1.b7cdfd9d7bdbbp-34, 0x1.000000006df38p+0},  // 1e-10
    {-0x1.b7cdfd9d7bdbbp-34, 0x1.ffffffff24190p-1},
    {0x1.0000000000000p-1, 0x1.a61298e1e069cp+0},  // 0.5
    {-0x1.0000000000000p-1, 0x1.368b2fc6f960ap-1},
    {0x1.0000000000000p+0, 0x1.5bf0a8b145769p+1},  // 1
    {-0x1.0000000000000p+0, 0x1.78b56362cef38p-2},
    {0x1.62e42fefa39efp-2, 0x1.6a09e667f3bccp+0},  // ln 2 / 2
    {0x1.4000000000000p+1, 0x1.85d6fd931e0bbp+3},
    {-0x1.d000000000000p+2, 0x1.7455fe323fafdp-11},  // -7.25
    {0x1.4000000000000p+3, 0x1.5829dcf950560p+14},
    {0x1.9000000000000p+6, 0x1.3494a9b171bf5p+144},  // 100
    {-0x1.9000000000000p+6, 0x1.a8c1f14e2af5dp-145},
    {0x1.5e00000000000p+9, 0x1.d945df4f8ec8ep+1009},  // 700
    {-0x1.5e00000000000p+9, 0x1.14f2b0fb9307fp-1010},
    {-0x1.5555555555555p-2, 0x1.6edd3122f2ea5p-1},  // -1/3
    {-0x1.999999999999ap-7, 0x1.f9a3cc26c0f05p-1},
    {-0x1.2c00000000000p+5, 0x1.dd5c566301ec8p-55},   // -37.5
    {0x1.62c0000000000p+9, 0x1.81e9b4b52d0c9p+1023},  // 709.5
};
constexpr Case kExp10s[] = {
    {-0x1.8000000000000p+1, 0x1.0624dd2f1a9fcp-10},  {-0x1.0000000000000p-2, 0x1.1feb33c1c381ep-1},   // -3, -0.25
    {-0x1.999999999999ap-4, 0x1.96b230bcdc434p-1},   {0x0.0p+0, 0x1.0000000000000p+0},                // -0.1, 0
    {0x1.3333333333333p-2, 0x1.fec982d5bb8afp+0},    {0x1.0000000000000p+0, 0x1.4000000000000p+3},    // 0.3, 1
    {0x1.0000000000000p+1, 0x1.9000000000000p+6},    {-0x1.9000000000000p+3, 0x1.640a72acc33c6p-42},  // 2, -12.5
    {0x1.e000000000000p+3, 0x1.c6bf526340000p+49},   {0x1.2c00000000000p+8, 0x1.7e43c8800759cp+996},  // 15, 300
    {-0x1.2c00000000000p+8, 0x1.56e1fc2f8f359p-997}, {-0x1.65fd8adab9f56p-5, 0x1.cefcfd5da6823p-1},   // -300, -0.0437
};
constexpr Case kTans[] = {
    {0x1.5798ee2308c3ap-27, 0x1.5798ee2308c3ap-27}, {0x1.999999999999ap-4, 0x1.9af8877430b80p-4},   // 1e-8, 0.1
    {0x1.0c152382d7365p-2, 0x1.126145e9ecd56p-2},   {0x1.0000000000000p-1, 0x1.17b4f5bf3474ap-1},   // 15 degrees, 0.5
    {0x1.921fb54442d18p-1, 0x1.fffffffffffffp-1},   {0x1.0000000000000p+0, 0x1.8eb245cbee3a6p+0},   // pi/4, 1
    {0x1.8000000000000p+0, 0x1.c33ed50b88777p+3},   {0x1.921fb54442d18p+0, 0x1.d02967c31cdb5p+53},  // 1.5, pi/2
    {0x1.0000000000000p+1, -0x1.17af62e0950f8p+1},  {0x1.8000000000000p+1, -0x1.23ef71254b86fp-3},  // 2, 3
    {-0x1.999999999999ap-2, -0x1.b0f0b49dcdcd8p-2}, {0x1.4000000000000p+3, 0x1.4bf5f34be3782p-1},   // -0.4, 10
    {0x1.9000000000000p+6, -0x1.2ca74d62b5d38p-1},  {0x1.657184ae74487p-2, 0x1.74b49cf3902d4p-2},   // 100, 20 degrees
};

TEST(PlainMath, ExpAndExp10AreCorrectlyRoundedAtKnownValues) {
  for (const Case& c : kExps) EXPECT_EQ(exp(c.x), c.y) << std::hexfloat << c.x;
  for (const Case& c : kExp10s) EXPECT_EQ(exp10(c.x), c.y) << std::hexfloat << c.x;
  EXPECT_EQ(exp(710.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(exp(-746.0), 0.0);
  EXPECT_GT(exp(-744.0), 0.0);  // subnormal
  EXPECT_TRUE(std::isnan(exp(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_EQ(exp10(309.0), std::numeric_limits<double>::infinity());
}

TEST(PlainMath, TanIsCorrectlyRoundedAtKnownValues) {
  for (const Case& c : kTans) EXPECT_EQ(tan(c.x), c.y) << std::hexfloat << c.x;
  EXPECT_TRUE(std::isnan(tan(2e6)));
}

// Between the known values: e^a e^b = e^(a+b) and 10^x = e^(x ln 10) to an ulp or two, over
// the exponents the physics tables take (Gaussian taps, warming, fabrics' losses).
TEST(PlainMath, ExpAgreesWithItself) {
  for (double x = -40.0; x <= 5.0; x += 0.0123457) {
    EXPECT_NEAR(exp(x) * exp(-x), 1.0, 4e-16) << x;
    EXPECT_NEAR(exp10(x) / exp(x * 2.302585092994046), 1.0, 1e-13) << x;  // x ln 10's rounding
  }
}

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
