#include <algorithm>

#include "backend/reference/stages.h"

namespace portalsim::reference {

void pool(const Catalogue& cat, const std::vector<std::vector<uint8_t>>& views, const FeatureLayout& f, float* row) {
  const int n = f.block;
  int k = 0;
  for (int view : f.pooled) {
    const Sensor& s = cat.sensors[view];
    const std::vector<uint8_t>& img = views[view];
    // The view's own grid: blocks until its edges, the last ones partial.
    for (int by = 0; by * n < s.height; ++by)
      for (int bx = 0; bx * n < s.width; ++bx) {
        double sum = 0;
        int count = 0;
        for (int y = by * n; y < std::min(s.height, (by + 1) * n); ++y)
          for (int x = bx * n; x < std::min(s.width, (bx + 1) * n); ++x) {
            sum += img[static_cast<size_t>(y) * s.width + x];
            ++count;
          }
        row[k++] = static_cast<float>(sum / count);
      }
  }
  // Each region's mean, in the pooled view that sees it.
  for (int r = 0; r < f.regions; ++r) {
    double mean = 0;
    for (int view : f.pooled) {
      const Sensor& s = cat.sensors[view];
      if (!s.sees(r)) continue;
      const Rect& rc = s.rects[r];
      double sum = 0;
      for (int y = rc.y; y < rc.y + rc.h; ++y)
        for (int x = rc.x; x < rc.x + rc.w; ++x) sum += views[view][static_cast<size_t>(y) * s.width + x];
      mean = sum / (static_cast<double>(rc.w) * rc.h);
      break;
    }
    row[k++] = static_cast<float>(mean);
  }
}

}  // namespace portalsim::reference
