// The procedural images' hashing and texture (assets/procedural*.cpp): an integer hash,
// value noise and the helpers every family shares. Internal to host/assets/.
#pragma once
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "scene/sensor.h"

namespace portalsim::procedural::detail {

// Refuse absurd sizes with an exception rather than an allocation failure deep inside.
inline constexpr int64_t kMaxPixels = int64_t{1} << 28;

// Added to a body's texture seeds where it is seen from the back.
inline constexpr uint64_t kBackSeed = 0x6261636bull;  // "back"

// Column x's centre in the field, pu field units a pixel: a back view sees the field
// mirrored, its left edge the field's right.
inline double field_u(const Frame& field, bool back, double pu, int x) {
  return back ? field.x + field.w - (x + 0.5) * pu : (x + 0.5) * pu + field.x;
}

inline void check_size(int w, int h, const char* what) {
  if (w < 1 || h < 1) throw std::invalid_argument(std::string(what) + ": width and height must be at least 1");
  if (static_cast<int64_t>(w) * h > kMaxPixels) throw std::invalid_argument(std::string(what) + ": image too large");
}

// ---- hashing and texture -------------------------------------------------------------

inline uint64_t mix64(uint64_t z) {  // splitmix64 finaliser
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// One finaliser over a lattice-scrambled key: cheap, and no visible pattern for texture.
inline uint64_t hash3(int64_t x, int64_t y, uint64_t seed) {
  const uint64_t k = static_cast<uint64_t>(x) * 0xd1b54a32d192ed03ULL ^
                     static_cast<uint64_t>(y) * 0xabc98388fb8fac03ULL ^ seed * 0x8cb92ba72f3d8dd7ULL;
  return mix64(k ^ (k >> 29));
}

// Uniform in [0, 1) and [-1, 1).
inline double hash01(int64_t x, int64_t y, uint64_t seed) {
  return static_cast<double>(hash3(x, y, seed) >> 11) * (1.0 / 9007199254740992.0);
}
inline double hash_signed(int64_t x, int64_t y, uint64_t seed) { return 2.0 * hash01(x, y, seed) - 1.0; }

inline double clamp01(double t) { return t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t); }
inline double smooth(double t) {
  t = clamp01(t);
  return t * t * (3.0 - 2.0 * t);
}
inline double smoothstep(double e0, double e1, double x) { return smooth((x - e0) / (e1 - e0)); }
inline double lerp(double a, double b, double t) { return a + (b - a) * t; }

// Bilinear value noise with a smooth fade, in [-1, 1], along one row (y fixed): the lattice
// row and its fade once, a cell's four corner hashes once while x stays in the cell (the body
// views draw whole rows of it).
class NoiseRow {
 public:
  NoiseRow(double y, uint64_t seed) : seed_(seed) {
    const double fy = std::floor(y);
    iy_ = static_cast<int64_t>(fy);
    ty_ = smooth(y - fy);
  }
  double operator()(double x) {
    const double fx = std::floor(x);
    const auto ix = static_cast<int64_t>(fx);
    if (!cached_ || ix != ix_) {
      a_ = hash_signed(ix, iy_, seed_), b_ = hash_signed(ix + 1, iy_, seed_);
      c_ = hash_signed(ix, iy_ + 1, seed_), d_ = hash_signed(ix + 1, iy_ + 1, seed_);
      ix_ = ix;
      cached_ = true;
    }
    const double tx = smooth(x - fx);
    return lerp(lerp(a_, b_, tx), lerp(c_, d_, tx), ty_);
  }

 private:
  uint64_t seed_;
  int64_t iy_ = 0, ix_ = 0;
  double ty_ = 0, a_ = 0, b_ = 0, c_ = 0, d_ = 0;
  bool cached_ = false;
};
inline double value_noise(double x, double y, uint64_t seed) { return NoiseRow(y, seed)(x); }

// Two octaves, still roughly in [-1, 1]; and along one row.
class FbmRow {
 public:
  FbmRow(double y, uint64_t seed) : first_(y, seed), second_(2.03 * y - 5.3, seed + 1) {}
  double operator()(double x) { return 0.67 * first_(x) + 0.33 * second_(2.03 * x + 17.1); }

 private:
  NoiseRow first_, second_;
};
inline double fbm(double x, double y, uint64_t seed) { return FbmRow(y, seed)(x); }

// Triangle wave in [0, 1] with period 1, smoothed to a cosine-like shape (1 at integers).
inline double wave(double t) {
  const double f = t - std::floor(t);
  return smooth(std::fabs(2.0 * f - 1.0));
}

inline uint8_t to_u8(double v) {
  if (!(v > 0.0)) return 0;  // also maps NaN to 0
  if (v >= 255.0) return 255;
  return static_cast<uint8_t>(std::floor(v + 0.5));
}

}  // namespace portalsim::procedural::detail
