// Procedural default images. Geometry is signed distance fields (negative inside) built
// from a handful of primitives; texture comes from an integer hash, so the bytes depend
// only on IEEE arithmetic (+, *, /, sqrt, floor), never on libm or a platform RNG: the
// pose's and the folds' sines are base/plain_math.h's, made of those operations alone.
// This file: the noise patterns; the families are procedural_body.cpp (the body),
// procedural_shapes.cpp (the objects), procedural_palette.cpp (palettes and folds) and the
// headers procedural_noise.h (hashing, texture) and procedural_sdf.h (distance primitives).
#include "assets/procedural.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "assets/procedural_noise.h"
#include "assets/procedural_sdf.h"

namespace portalsim::procedural {

using namespace detail;

Image noise_pattern(int k, int size) {
  if (k < 0 || k >= kProceduralNoisePatterns)
    throw std::invalid_argument("noise_pattern: k must be in 0.." + std::to_string(kProceduralNoisePatterns - 1));
  check_size(size, size, "noise_pattern");
  Image img(size, size, 1, 128);
  if (size < 3) return img;  // all border
  const uint64_t seed = 0x6e6f697365ULL + static_cast<uint64_t>(k);
  const double n = size, half = 0.5 * (size - 1);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      // Envelope: flat in the middle, smoothly to exactly 0 on the border pixels.
      const double ex = std::fabs(x - half) / half, ey = std::fabs(y - half) / half;
      const double env = smoothstep(0.0, 0.45, 1.0 - ex) * smoothstep(0.0, 0.45, 1.0 - ey);
      if (env <= 0.0) continue;
      double a = 0.0;
      switch (k) {
        case 0:  // fine speckle: independent pixels, a few strong ones
        {
          const double h = hash_signed(x, y, seed);
          a = h * std::fabs(h) * 0.6 + 0.4 * h;
          break;
        }
        case 1:  // horizontal streaks: long along x, a few pixels across
          a = 0.95 * value_noise(x / std::max(6.0, n / 4.0), y / 2.2, seed) + 0.12 * hash_signed(x, y, seed + 1);
          break;
        case 2: {  // low-frequency blotches, contrast-stretched
          const double b = fbm(x / std::max(3.0, n / 5.0), y / std::max(3.0, n / 5.0), seed);
          a = std::clamp(1.8 * b, -1.0, 1.0);
          break;
        }
        case 3: {  // concentric rings, slightly wobbly
          const double dx = x - half, dy = y - half;
          const double r = len(dx, dy) + 1.2 * value_noise(x / 8.0, y / 8.0, seed);
          a = 2.0 * wave(r / std::max(3.0, n / 10.0)) - 1.0;
          break;
        }
        default:  // vertical banding: columns of varying brightness
          a = 0.75 * value_noise(x / 2.5, y / std::max(8.0, n / 3.0), seed) +
              0.25 * value_noise(x / 7.0, 0.5, seed + 1);
          a = std::clamp(1.4 * a, -1.0, 1.0);
          break;
      }
      img.at(x, y) = to_u8(128.0 + 45.0 * env * std::clamp(a, -1.0, 1.0));
    }
  }
  return img;
}

}  // namespace portalsim::procedural
