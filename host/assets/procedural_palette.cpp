// The IR palettes, and the clothing's folds and seams over a view's body.
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

#include "assets/procedural.h"
#include "assets/procedural_noise.h"
#include "base/plain_math.h"

namespace portalsim::procedural {

using namespace detail;

namespace {

struct Stop {
  int at;
  int r, g, b;
};
constexpr Stop kIron[] = {{0, 0, 0, 0},       {36, 22, 0, 92},    {78, 92, 0, 150},    {118, 168, 6, 140},
                          {152, 218, 38, 64}, {186, 246, 108, 0}, {222, 255, 196, 24}, {255, 255, 252, 236}};
constexpr Stop kGray[] = {{0, 0, 0, 0}, {255, 255, 255, 255}};  // white hot
// Rainbow: blue (cold), cyan, green, yellow, red, white (hot).
constexpr Stop kRainbow[] = {{0, 0, 0, 128},     {40, 0, 0, 255},   {92, 0, 224, 255},   {140, 0, 224, 0},
                             {184, 255, 240, 0}, {228, 255, 32, 0}, {255, 255, 255, 255}};

}  // namespace

Image fold_pattern(const Image& base, const Sensor& view, int body_lo, int body_hi, int texture) {
  check_size(base.width, base.height, "fold pattern");
  Image out(base.width, base.height, 1, 0);
  const uint64_t seed = 0xf01d5ULL + static_cast<uint64_t>(texture);
  const double phase = 2.0 * std::numbers::pi * hash01(texture, 1, seed);
  const double per_col = std::abs(view.field_per_col());
  constexpr double kCreaseEvery = 22.0, kCreaseWidth = 0.3;  // field units; its share of the period
  constexpr double kSeamIn = 3.0, kSeamWidth = 1.5, kCentreWidth = 2.0, kCentreFrom = 40.0;
  // Crease k lies across the body near v = 22 k, bent with a wavelength, height and phase of
  // its own, and of its own depth along it: per crease and column, its bend and depth.
  const double v0 = view.field_row(0.5), v1 = view.field_row(base.height - 0.5);
  const int64_t k0 = static_cast<int64_t>(std::floor(std::min(v0, v1) / kCreaseEvery)) - 1;
  const int64_t k1 = static_cast<int64_t>(std::floor(std::max(v0, v1) / kCreaseEvery)) + 1;
  const size_t W = static_cast<size_t>(base.width);
  std::vector<double> bend(static_cast<size_t>(k1 - k0 + 1) * W), depth(bend.size());
  for (int64_t k = k0; k <= k1; ++k) {
    const auto own = [&](int j) { return hash01(k, j, seed); };
    const double height = 2.0 + 3.0 * own(3), wave = 25.0 + 20.0 * own(4), shift = own(5);
    const double deep = 0.35 + 0.65 * own(2), stretch = 40.0 + 30.0 * own(6), at = own(7);
    for (size_t x = 0; x < W; ++x) {
      const double u = view.field_col(static_cast<double>(x) + 0.5);
      const size_t i = static_cast<size_t>(k - k0) * W + x;
      bend[i] = height * plain::sin(2.0 * std::numbers::pi * (u / wave + shift) + phase);
      depth[i] = deep * (0.5 + 0.5 * plain::sin(2.0 * std::numbers::pi * (u / stretch + at)));
    }
  }
  for (int y = 0; y < base.height; ++y) {
    const double v = view.field_row(y + 0.5);
    const int64_t near = static_cast<int64_t>(std::floor(v / kCreaseEvery));
    for (int a = 0; a < base.width;) {
      const auto body = [&](int x) { return base.at(x, y) >= body_lo && base.at(x, y) <= body_hi; };
      if (!body(a)) {
        ++a;
        continue;
      }
      int b = a;
      while (b < base.width && body(b)) ++b;
      const double run = (b - a) * per_col, centre = 0.5 * (a + b);
      for (int x = a; x < b; ++x) {
        // A crease's profile across it: (4 t (1 - t))^2 over t in [0, 1) of its width.
        double m = 0;
        for (int64_t k = near - 1; k <= near + 1; ++k) {
          const size_t i = static_cast<size_t>(k - k0) * W + static_cast<size_t>(x);
          const double t = ((v + bend[i]) / kCreaseEvery - static_cast<double>(k)) / kCreaseWidth;
          if (t < 0 || t >= 1) continue;
          const double bump = 4.0 * t * (1.0 - t);
          m = std::max(m, depth[i] * bump * bump);
        }
        const double in = std::min(x - a, b - 1 - x) * per_col + 0.5 * per_col;
        if (run >= 4 * kSeamIn && in >= kSeamIn && in < kSeamIn + kSeamWidth) m = 1;
        if (run >= kCentreFrom && std::abs(x + 0.5 - centre) * per_col < kCentreWidth / 2) m = 1;
        out.at(x, y) = static_cast<uint8_t>(std::lround(255.0 * clamp01(m)));
      }
      a = b;
    }
  }
  return out;
}

const char* palette_name(PaletteName p) {
  return p == PaletteName::gray ? "gray" : p == PaletteName::rainbow ? "rainbow" : "ironbow";
}

std::array<std::array<uint8_t, 3>, 256> ir_palette(PaletteName which) {
  const std::span<const Stop> stops = which == PaletteName::gray      ? std::span<const Stop>(kGray)
                                      : which == PaletteName::rainbow ? std::span<const Stop>(kRainbow)
                                                                      : std::span<const Stop>(kIron);
  std::array<std::array<uint8_t, 3>, 256> pal{};
  const size_t n = stops.size();
  for (int i = 0; i < 256; ++i) {
    size_t k = 0;
    while (k + 2 < n && i > stops[k + 1].at) ++k;
    const Stop& a = stops[k];
    const Stop& b = stops[k + 1];
    const double t = static_cast<double>(i - a.at) / (b.at - a.at);
    pal[i] = {to_u8(lerp(a.r, b.r, t)), to_u8(lerp(a.g, b.g, t)), to_u8(lerp(a.b, b.b, t))};
  }
  return pal;
}

}  // namespace portalsim::procedural
