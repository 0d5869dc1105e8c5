#include "sink/pooling.h"

#include <algorithm>
#include <cstdint>

namespace portalsim {

namespace {

// The kernels' mean_of (kernels/pool.cl).
float mean_of(uint32_t sum, int count) {
  const uint32_t q = sum / static_cast<uint32_t>(count), r = sum % static_cast<uint32_t>(count);
  return std::clamp(static_cast<float>(q) + static_cast<float>(r) / static_cast<float>(count), 0.0f, 255.0f);
}

float rect_mean(const Image& img, int x0, int y0, int x1, int y1) {
  uint32_t sum = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) sum += img.at(x, y);
  return mean_of(sum, (x1 - x0) * (y1 - y0));
}

}  // namespace

void pool_images(const Catalogue& cat, const FeatureLayout& lay, const std::vector<Image>& images, float* row) {
  int k = 0;
  for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
    const Sensor& s = cat.sensors[lay.pooled[slot]];
    for (int by = 0; by < lay.grids[slot].blocks_y; ++by)
      for (int bx = 0; bx < lay.grids[slot].blocks_x; ++bx) {
        const int x0 = bx * lay.block, y0 = by * lay.block;
        row[k++] =
            rect_mean(images[slot], x0, y0, std::min(x0 + lay.block, s.width), std::min(y0 + lay.block, s.height));
      }
  }
  for (int r = 0; r < lay.regions; ++r) {
    float mean = 0;
    for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
      const Sensor& s = cat.sensors[lay.pooled[slot]];
      if (!s.sees(r)) continue;
      const Rect& rc = s.rects[r];
      mean = rect_mean(images[slot], rc.x, rc.y, rc.x + rc.w, rc.y + rc.h);
      break;
    }
    row[k++] = mean;
  }
}

}  // namespace portalsim
