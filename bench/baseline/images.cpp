#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "baseline.h"
#include "philox_words.h"

namespace portalsim::baseline {

namespace {

// The kernels' Box-Muller pair (kernels/sensor_noise.cl): polynomial ln and sincos in
// float, the same operations in the same order.
inline void gauss_pair(uint32_t r0, uint32_t r1, float& g0, float& g1) {
  const float u1 = 1.0f - static_cast<float>(r0 >> 8) * (1.0f / 16777216.0f);
  const float u2 = static_cast<float>(r1 >> 8) * (1.0f / 16777216.0f);
  const int32_t bits = std::bit_cast<int32_t>(u1);
  int32_t e = ((bits >> 23) & 0xff) - 127;
  float m = std::bit_cast<float>((bits & 0x7fffff) | 0x3f800000);
  if (m > 1.41421356f) {
    m = m * 0.5f;
    e = e + 1;
  }
  const float s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
  const float p = 2.0f * s * (1.0f + s2 * (0.33333333f + s2 * (0.2f + s2 * (0.14285714f + s2 * 0.11111111f))));
  const float ln = static_cast<float>(e) * 0.69314718f + p;
  const float rad = std::sqrt(-2.0f * ln);
  const float t = u2 - std::nearbyint(u2);
  const float kf = std::nearbyint(t * 4.0f);
  const float a = (t - kf * 0.25f) * 6.2831853f, a2 = a * a;
  const float sn = a * (1.0f + a2 * (-0.16666667f + a2 * (8.3333333e-3f + a2 * (-1.9841270e-4f + a2 * 2.7557319e-6f))));
  const float cs =
      1.0f + a2 * (-0.5f + a2 * (4.1666667e-2f + a2 * (-1.3888889e-3f + a2 * (2.4801587e-5f + a2 * -2.7557319e-7f))));
  // Rotated by the quadrant, branch-free so that the loop over pairs vectorises.
  const int32_t k = static_cast<int32_t>(kf) & 3;
  const float c = k == 0 ? cs : k == 1 ? -sn : k == 2 ? -cs : sn;
  const float si = k == 0 ? sn : k == 1 ? cs : k == 2 ? -sn : -cs;
  g0 = rad * c;
  g1 = rad * si;
}

struct Layer {
  const Image* sprite;
  int x0, y0, tx0, ty0;
};

}  // namespace

void render_images(const Catalogue& cat, const AssetSet& assets, const SceneBatch& batch, const ModelSettings& m,
                   BatchOutput& out) {
  if (m.moves_sprites()) throw std::invalid_argument("the image baseline places sprites on whole pixels only");
  const size_t n = batch.size();
  const float alpha = static_cast<float>(cat.images.alpha), sigma = static_cast<float>(m.pixel_sigma);
  const int tile = cat.images.noise_size, patterns = static_cast<int>(cat.noise.size());
  int max_width = 1;
  for (const Sensor& s : cat.sensors) max_width = std::max(max_width, s.width);

#pragma omp parallel
  {
    std::vector<float> v(max_width), nsum(max_width), g(max_width + 2);
    std::vector<uint32_t> w0(max_width / 2 + 2), w1(max_width / 2 + 2);
    std::vector<Layer> layers;
#pragma omp for schedule(dynamic, 16)
    for (size_t i = 0; i < n; ++i) {
      const uint64_t index = batch.first_index + i;
      const int16_t* objects = &batch.objects[i * batch.regions];
      uint32_t r0, r1;
      philox_words(0, PS_STREAM_NOISE_PATTERN, index, m.seed, r0, r1);
      const int pattern = static_cast<int>((static_cast<uint64_t>(r0) * static_cast<uint32_t>(patterns)) >> 32);
      for (size_t k = 0; k < cat.sensors.size(); ++k) {
        const Sensor& s = cat.sensors[k];
        const int W = s.width, H = s.height;
        const Image& base = assets.bases[batch.subject[i]][k];
        uint8_t* img = out.views[k].pixels.data() + i * s.pixels();
        layers.clear();
        for (int r = 0; r < batch.regions; ++r) {
          if (objects[r] < 0 || !s.sees(r)) continue;
          const Image& sp = assets.sprite(s, objects[r]);
          const Rect& rc = s.rects[r];
          const int x0 = rc.x + ((rc.w - sp.width) >> 1), y0 = rc.y + ((rc.h - sp.height) >> 1);
          layers.push_back({&sp, x0, y0, x0 + (sp.width >> 1) - (tile >> 1), y0 + (sp.height >> 1) - (tile >> 1)});
        }
        const bool tiles = s.pattern_noise && m.pattern_noise;
        const float gain = static_cast<float>(cat.noise[pattern].gain);
        const Image& noise = assets.noise[pattern];
        for (int y = 0; y < H; ++y) {
          const uint8_t* b = base.pixels.data() + static_cast<size_t>(y) * W;
          uint8_t* o = img + static_cast<size_t>(y) * W;
          // Only the span that layers and tiles cover (all of the row under noise) changes.
          int lo = sigma > 0 ? 0 : W, hi = sigma > 0 ? W : 0;
          for (const Layer& l : layers) {
            if (y >= l.y0 && y < l.y0 + l.sprite->height)
              lo = std::min(lo, l.x0), hi = std::max(hi, l.x0 + l.sprite->width);
            if (tiles && y >= l.ty0 && y < l.ty0 + tile) lo = std::min(lo, l.tx0), hi = std::max(hi, l.tx0 + tile);
          }
          lo = std::max(lo, 0);
          hi = std::min(hi, W);
          std::memcpy(o, b, W);
          if (lo >= hi) continue;
          for (int x = lo; x < hi; ++x) v[x] = b[x];
          for (const Layer& l : layers) {
            const Image& sp = *l.sprite;
            if (y < l.y0 || y >= l.y0 + sp.height) continue;
            const uint8_t* row = sp.pixels.data() + static_cast<size_t>(y - l.y0) * sp.width * 2;
            const int xa = std::max(0, l.x0), xb = std::min(W, l.x0 + sp.width);
            for (int x = xa; x < xb; ++x) {
              const float a = alpha * static_cast<float>(row[2 * (x - l.x0) + 1]) / 255.0f;
              v[x] = std::fma(a, static_cast<float>(row[2 * (x - l.x0)]) - v[x], v[x]);
            }
          }
          if (tiles) {
            int tlo = W, thi = 0;
            for (const Layer& l : layers)
              if (y >= l.ty0 && y < l.ty0 + tile) tlo = std::min(tlo, l.tx0), thi = std::max(thi, l.tx0 + tile);
            tlo = std::max(tlo, 0);
            thi = std::min(thi, W);
            for (int x = tlo; x < thi; ++x) nsum[x] = 0.0f;
            for (const Layer& l : layers) {
              if (y < l.ty0 || y >= l.ty0 + tile) continue;
              const uint8_t* row = noise.pixels.data() + static_cast<size_t>(y - l.ty0) * tile;
              const int xa = std::max(0, l.tx0), xb = std::min(W, l.tx0 + tile);
              for (int x = xa; x < xb; ++x) nsum[x] += static_cast<float>(row[x - l.tx0]) - 128.0f;
            }
            for (int x = tlo; x < thi; ++x) v[x] = v[x] + gain * nsum[x];
          }
          if (sigma > 0) {
            // Pairs follow the pixel index y W + x; an odd W starts rows mid-pair.
            const int p0 = y * W, first_pair = p0 >> 1, pairs = ((p0 + W - 1) >> 1) - first_pair + 1;
            const uint32_t view_bits = static_cast<uint32_t>(k) << PS_PIXEL_NOISE_VIEW_SHIFT;
            for (int q = 0; q < pairs; ++q)
              philox_words(view_bits | static_cast<uint32_t>(first_pair + q), PS_STREAM_PIXEL_NOISE, index, m.seed,
                           w0[q], w1[q]);
            for (int q = 0; q < pairs; ++q) gauss_pair(w0[q], w1[q], g[2 * q], g[2 * q + 1]);
            const float* gx = g.data() + (p0 & 1);
            for (int x = 0; x < W; ++x) v[x] = std::fma(sigma, gx[x], v[x]);
          }
          for (int x = lo; x < hi; ++x) o[x] = static_cast<uint8_t>(std::clamp(std::floor(v[x] + 0.5f), 0.0f, 255.0f));
        }
      }
    }
  }
}

}  // namespace portalsim::baseline
