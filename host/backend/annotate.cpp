#include "backend/annotate.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "backend/reference/stages.h"
#include "base/parallel.h"

namespace portalsim {

namespace {

// Paints region + 1 over every pixel the placed sprite covers (coverage > 0), as the
// reference's composite samples it.
void paint(const reference::Placed& p, bool bilinear, int W, int H, uint8_t id, uint8_t* mask) {
  const Image& sp = *p.sprite;
  const auto cov = [&](int i, int j) { return i >= 0 && j >= 0 && i < sp.width && j < sp.height && sp.at(i, j, 1); };
  if (!bilinear) {
    const int ox = p.x0 + static_cast<int>(std::floor(p.dx + 0.5));
    const int oy = p.y0 + static_cast<int>(std::floor(p.dy + 0.5));
    for (int y = std::max(0, oy); y < std::min(H, oy + sp.height); ++y)
      for (int x = std::max(0, ox); x < std::min(W, ox + sp.width); ++x)
        if (sp.at(x - ox, y - oy, 1)) mask[static_cast<size_t>(y) * W + x] = id;
    return;
  }
  // A texel counts where its weight (1 - t or t, per axis) is non-zero.
  const double fx = p.x0 + p.dx, fy = p.y0 + p.dy;
  for (int y = std::max(0, static_cast<int>(std::floor(fy)) - 1);
       y < std::min(H, static_cast<int>(std::floor(fy)) + sp.height + 2); ++y) {
    const double sy = y - fy;
    const int j0 = static_cast<int>(std::floor(sy));
    const bool ty = sy - j0 > 0;
    for (int x = std::max(0, static_cast<int>(std::floor(fx)) - 1);
         x < std::min(W, static_cast<int>(std::floor(fx)) + sp.width + 2); ++x) {
      const double sx = x - fx;
      const int i0 = static_cast<int>(std::floor(sx));
      const bool tx = sx - i0 > 0;
      if (cov(i0, j0) || (tx && cov(i0 + 1, j0)) || (ty && cov(i0, j0 + 1)) || (tx && ty && cov(i0 + 1, j0 + 1)))
        mask[static_cast<size_t>(y) * W + x] = id;
    }
  }
}

}  // namespace

void annotate(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model, const SceneBatch& batch,
              std::vector<ViewAnnotations>& out, unsigned threads) {
  const size_t n = batch.size();
  out.resize(cat.sensors.size());
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& sensor = cat.sensors[k];
    ViewAnnotations& va = out[k];
    const int W = sensor.width, H = sensor.height;
    const size_t px = static_cast<size_t>(W) * H;
    va.width = W;
    va.height = H;
    va.masks.assign(n * px, 0);
    std::vector<std::vector<Annotation>> per(n);
    parallel_for(n, n >= 256 ? threads : 1, [&](size_t lo, size_t hi) {
      for (size_t i = lo; i < hi; ++i) {
        const Scenario s = batch.at(i);
        const reference::ViewScene vs =
            reference::view_scene(cat, assets, model, static_cast<int>(k), s, batch.first_index + i);
        uint8_t* mask = va.masks.data() + i * px;
        std::vector<Annotation> items;
        size_t p = 0;
        for (int r = 0; r < kRegions; ++r) {
          const int16_t v = s.objects[r];
          if (v == kNoObject || !sensor.sees(r)) continue;
          const reference::Placed& pl = vs.placed[p++];
          paint(pl, model.bilinear, W, H, static_cast<uint8_t>(r + 1), mask);
          Annotation a;
          a.scenario = static_cast<uint32_t>(i);
          a.region = static_cast<uint8_t>(r);
          a.object = static_cast<int16_t>(cat.variant_list[v].object);
          a.drawing = static_cast<int16_t>(cat.variant_list[v].variant);
          a.dx = model.bilinear ? pl.dx : std::floor(pl.dx + 0.5);
          a.dy = model.bilinear ? pl.dy : std::floor(pl.dy + 0.5);
          items.push_back(a);
        }
        // Boxes and areas of what each region owns once every object is painted.
        std::vector<int> x0(kRegions + 1, W), y0(kRegions + 1, H), x1(kRegions + 1, -1), y1(kRegions + 1, -1);
        std::vector<uint32_t> area(kRegions + 1, 0);
        if (!items.empty())
          for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
              const uint8_t id = mask[static_cast<size_t>(y) * W + x];
              if (!id) continue;
              ++area[id];
              x0[id] = std::min(x0[id], x);
              x1[id] = std::max(x1[id], x);
              y0[id] = std::min(y0[id], y);
              y1[id] = std::max(y1[id], y);
            }
        for (Annotation& a : items) {
          const int id = a.region + 1;
          a.area = area[id];
          a.x = x0[id];
          a.y = y0[id];
          a.w = x1[id] - x0[id] + 1;
          a.h = y1[id] - y0[id] + 1;
        }
        std::erase_if(items, [](const Annotation& a) { return a.area == 0; });
        per[i] = std::move(items);
      }
    });
    va.items.clear();
    va.first.assign(n + 1, 0);
    for (size_t i = 0; i < n; ++i) {
      va.first[i] = static_cast<uint32_t>(va.items.size());
      va.items.insert(va.items.end(), per[i].begin(), per[i].end());
    }
    va.first[n] = static_cast<uint32_t>(va.items.size());
  }
}

}  // namespace portalsim
