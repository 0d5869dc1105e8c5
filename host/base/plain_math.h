// ln, exp, 10^x, sin, cos and tan from + - * / alone, so that the bytes they set (a body's
// pose, its drawn shape, the clothing's folds and fabrics' losses, the physics model's
// tables) do not depend on which libm the build links.
// Each is evaluated in double-double arithmetic and rounded once at the end: within 0.5
// ulp plus about 1e-20 relative, so correctly rounded but for rare near-halfway cases, and
// the same on any IEEE-754 machine (the file is built with -ffp-contract=off). glibc 2.36's
// log, sin and cos differ from these by one ulp on 0.08%, 0.14% and 0.14% of the 2^24
// inputs of the bodies' Box-Muller draws (glibc's the misrounded ones, against 300-bit
// values); no pinned output moved.
#pragma once

namespace portalsim::plain {

// The natural logarithm of a finite x > 0 (NaN for x <= 0 or NaN, x for +inf).
double log(double x);

// e^x and 10^x (0 below the smallest subnormal, +inf past the largest double; NaN for NaN).
double exp(double x);
double exp10(double x);

// sin and cos of x in radians, for |x| <= 1e6 (NaN beyond: no caller goes near it).
struct SinCos {
  double sin, cos;
};
SinCos sincos(double x);
double sin(double x);
double cos(double x);
// tan of x in radians, for |x| <= 1e6.
double tan(double x);

}  // namespace portalsim::plain
