#include "backend/opencl/raw_grid_pooling.h"

#include <algorithm>
#include <cmath>

namespace portalsim {

namespace {

// Each pixel's interpolation weights along one axis (size pixels over raw cells), as
// stage_mmw_display samples: centre (p + 1/2) raw / size - 1/2, held inside [0, raw - 1].
std::vector<std::vector<double>> axis_weights(int size, int raw) {
  std::vector<std::vector<double>> w(static_cast<size_t>(size), std::vector<double>(static_cast<size_t>(raw), 0.0));
  const double step = static_cast<double>(raw) / size;
  for (int p = 0; p < size; ++p) {
    const double u = std::clamp((p + 0.5) * step - 0.5, 0.0, static_cast<double>(raw - 1));
    const int i0 = static_cast<int>(u), i1 = std::min(i0 + 1, raw - 1);
    const double t = u - i0;
    w[p][i0] += 1.0 - t;
    w[p][i1] += t;
  }
  return w;
}

// The summed weights of pixels [lo, hi) along an axis.
std::vector<double> span(const std::vector<std::vector<double>>& w, int lo, int hi) {
  std::vector<double> s(w.empty() ? 0 : w[0].size(), 0.0);
  for (int p = lo; p < hi; ++p)
    for (size_t c = 0; c < s.size(); ++c) s[c] += w[p][c];
  return s;
}

}  // namespace

RawGridPooling raw_grid_pooling(const Sensor& s, const FeatureLayout& lay, int slot, int raw_width, int raw_height) {
  const std::vector<std::vector<double>> wx = axis_weights(s.width, raw_width), wy = axis_weights(s.height, raw_height);
  RawGridPooling p;
  // The mean over a rectangle: the outer product of its column and row weights.
  const auto add = [&](int x0, int y0, int x1, int y1, int column) {
    const std::vector<double> sx = span(wx, x0, x1), sy = span(wy, y0, y1);
    const double count = static_cast<double>(x1 - x0) * (y1 - y0);
    p.first.push_back(static_cast<int32_t>(p.cells.size()));
    p.columns.push_back(column);
    for (int j = 0; j < raw_height; ++j)
      for (int i = 0; i < raw_width; ++i)
        if (sy[j] != 0 && sx[i] != 0) {
          p.cells.push_back(j * raw_width + i);
          p.weights.push_back(count > 0 ? sy[j] * sx[i] / count : 0.0);
        }
  };
  for (int by = 0; by < lay.blocks_y; ++by)
    for (int bx = 0; bx < lay.blocks_x; ++bx) {
      const int x0 = bx * lay.block, y0 = by * lay.block;
      add(x0, y0, std::min(x0 + lay.block, s.width), std::min(y0 + lay.block, s.height),
          slot * lay.blocks_per_view() + by * lay.blocks_x + bx);
    }
  for (int r = 0; r < kRegions; ++r)
    if (s.sees(r)) {
      const Rect& rc = s.rects[r];
      add(rc.x, rc.y, rc.x + rc.w, rc.y + rc.h, lay.block_features() + r);
    }
  p.first.push_back(static_cast<int32_t>(p.cells.size()));
  return p;
}

}  // namespace portalsim
