#include "backend/annotate.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "backend/reference/stages.h"
#include "base/parallel.h"

namespace portalsim {

namespace {

// A sprite's covered texels (alpha > 0) as runs [a, b) per row.
struct Runs {
  std::vector<uint32_t> first;  // height + 1: row j's runs are [first[j], first[j + 1])
  std::vector<std::pair<int, int>> runs;
  explicit Runs(const Image& sp) {
    for (int j = 0; j < sp.height; ++j) {
      first.push_back(static_cast<uint32_t>(runs.size()));
      for (int i = 0; i < sp.width;) {
        if (!sp.at(i, j, 1)) {
          ++i;
          continue;
        }
        const int a = i;
        while (i < sp.width && sp.at(i, j, 1)) ++i;
        runs.emplace_back(a, i);
      }
    }
    first.push_back(static_cast<uint32_t>(runs.size()));
  }
};

// What one object painted: its pixels' count and box (inclusive), before later objects.
struct Painted {
  uint32_t area = 0;
  int x0 = INT32_MAX, y0 = INT32_MAX, x1 = -1, y1 = -1;
  void add(int xa, int xb, int y) {  // pixels [xa, xb) of row y
    area += static_cast<uint32_t>(xb - xa);
    x0 = std::min(x0, xa);
    x1 = std::max(x1, xb - 1);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
  bool meets(const Painted& o) const { return area && o.area && x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1; }
};

// Paints region + 1 over every pixel the placed sprite covers (coverage > 0) as the
// reference's composite samples it: at integer placement the texel under the pixel; at
// bilinear placement, and for randomised objects at the sprite point the reference's
// inverse map gives, any of the four texels whose weight, computed as the reference
// computes it, is non-zero.
Painted paint(const reference::Placed& p, const Runs& runs, const ModelSettings& model, int W, int H, uint8_t id,
              uint8_t* mask) {
  const Image& sp = *p.sprite;
  const bool bilinear = model.bilinear;
  Painted out;
  const auto cov = [&](int i, int j) { return i >= 0 && j >= 0 && i < sp.width && j < sp.height && sp.at(i, j, 1); };
  if (model.transforms()) {
    const reference::SpriteMap map = reference::sprite_map(p, bilinear);
    for (int y = std::max(0, map.y0); y <= std::min(H - 1, map.y1); ++y) {
      uint8_t* row = mask + static_cast<size_t>(y) * W;
      for (int x = std::max(0, map.x0); x <= std::min(W - 1, map.x1); ++x) {
        double sx, sy;
        map.at(x, y, sx, sy);
        const int i = static_cast<int>(std::floor(sx)), j = static_cast<int>(std::floor(sy));
        const bool t = sx - i > 0, ty = sy - j > 0;
        if (cov(i, j) || (t && cov(i + 1, j)) || (ty && cov(i, j + 1)) || (t && ty && cov(i + 1, j + 1))) {
          row[x] = id;
          out.add(x, x + 1, y);
        }
      }
    }
    return out;
  }
  if (!bilinear) {
    const int ox = p.x0 + static_cast<int>(std::floor(p.dx + 0.5));
    const int oy = p.y0 + static_cast<int>(std::floor(p.dy + 0.5));
    for (int j = std::max(0, -oy); j < std::min(sp.height, H - oy); ++j)
      for (uint32_t k = runs.first[j]; k < runs.first[j + 1]; ++k) {
        const int xa = std::max(0, ox + runs.runs[k].first), xb = std::min(W, ox + runs.runs[k].second);
        if (xa >= xb) continue;
        std::memset(mask + static_cast<size_t>(oy + j) * W + xa, id, static_cast<size_t>(xb - xa));
        out.add(xa, xb, oy + j);
      }
    return out;
  }
  const double fx = p.x0 + p.dx, fy = p.y0 + p.dy;
  const int xs = std::max(0, static_cast<int>(std::floor(fx)) - 1),
            xe = std::min(W, static_cast<int>(std::floor(fx)) + sp.width + 2);
  // Per column, the texel column and whether its right neighbour has weight.
  std::vector<int> i0(static_cast<size_t>(std::max(0, xe - xs)));
  std::vector<char> tx(i0.size());
  for (int x = xs; x < xe; ++x) {
    const double sx = x - fx;
    i0[x - xs] = static_cast<int>(std::floor(sx));
    tx[x - xs] = sx - i0[x - xs] > 0;
  }
  for (int y = std::max(0, static_cast<int>(std::floor(fy)) - 1);
       y < std::min(H, static_cast<int>(std::floor(fy)) + sp.height + 2); ++y) {
    const double sy = y - fy;
    const int j0 = static_cast<int>(std::floor(sy));
    const bool ty = sy - j0 > 0;
    if (j0 < -1 || j0 >= sp.height) continue;
    uint8_t* row = mask + static_cast<size_t>(y) * W;
    for (int x = xs; x < xe; ++x) {
      const int i = i0[x - xs];
      const bool t = tx[x - xs];
      if (cov(i, j0) || (t && cov(i + 1, j0)) || (ty && cov(i, j0 + 1)) || (t && ty && cov(i + 1, j0 + 1))) {
        row[x] = id;
        out.add(x, x + 1, y);
      }
    }
  }
  return out;
}

}  // namespace

void annotate(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model, const SceneBatch& batch,
              std::vector<ViewAnnotations>& out, unsigned threads) {
  const size_t n = batch.size(), views = cat.sensors.size();
  out.resize(views);
  std::vector<std::vector<Runs>> runs(views);
  for (size_t k = 0; k < views; ++k) {
    const Sensor& sensor = cat.sensors[k];
    ViewAnnotations& va = out[k];
    // Masks left by the last batch are cleared where they were painted (below); new
    // ones come zeroed.
    const size_t px = sensor.pixels();
    if (va.width == sensor.width && va.height == sensor.height && va.painted.size() * px == va.masks.size()) {
      va.masks.resize(n * px);
      va.painted.resize(n);
    } else {
      va.masks.assign(n * px, 0);
      va.painted.assign(n, {});
    }
    va.width = sensor.width;
    va.height = sensor.height;
    for (size_t v = 0; v < cat.variant_list.size(); ++v)
      runs[k].emplace_back(assets.sprite(sensor.camera, static_cast<int>(v)));
  }
  // Up to one annotation per region, by scenario, then view; no allocation per image.
  // Kept between calls: a fresh megabyte per batch would cost page faults each time.
  // (Named through references: inside the workers' lambda a thread_local would be theirs.)
  static thread_local std::vector<std::array<Annotation, kRegions>> per_kept;
  static thread_local std::vector<uint8_t> count_kept;
  std::vector<std::array<Annotation, kRegions>>& per = per_kept;
  std::vector<uint8_t>& count = count_kept;
  per.resize(n * views);
  count.assign(n * views, 0);
  parallel_for(n, n >= 256 ? threads : 1, [&](size_t lo, size_t hi) {
    std::vector<Painted> painted;
    for (size_t i = lo; i < hi; ++i) {
      const Scenario s = batch.at(i);
      for (size_t k = 0; k < views; ++k) {
        const Sensor& sensor = cat.sensors[k];
        const int W = sensor.width, H = sensor.height;
        const reference::ViewScene vs =
            reference::view_scene(cat, assets, model, static_cast<int>(k), s, batch.first_index + i);
        uint8_t* mask = out[k].masks.data() + i * sensor.pixels();
        ViewAnnotations::Painted& dirty = out[k].painted[i];
        for (int b = 0; b < dirty.count; ++b) {
          const auto& [x0, y0, x1, y1] = dirty.box[b];
          for (int y = y0; y <= y1; ++y)
            std::memset(mask + static_cast<size_t>(y) * W + x0, 0, static_cast<size_t>(x1 - x0 + 1));
        }
        dirty.count = 0;
        std::array<Annotation, kRegions>& items = per[i * views + k];
        size_t m = 0;
        painted.clear();
        size_t p = 0;
        for (int r = 0; r < kRegions; ++r) {
          const int16_t v = s.objects[r];
          if (v == kNoObject || !sensor.sees(r)) continue;
          const reference::Placed& pl = vs.placed[p++];
          painted.push_back(paint(pl, runs[k][v], model, W, H, static_cast<uint8_t>(r + 1), mask));
          if (const Painted& d = painted.back(); d.area)
            dirty.box[dirty.count++] = {static_cast<int16_t>(d.x0), static_cast<int16_t>(d.y0),
                                        static_cast<int16_t>(d.x1), static_cast<int16_t>(d.y1)};
          Annotation& a = items[m++];
          a = Annotation{};
          a.scenario = static_cast<uint32_t>(i);
          a.region = static_cast<uint8_t>(r);
          a.object = static_cast<int16_t>(cat.variant_list[v].object);
          a.drawing = static_cast<int16_t>(cat.variant_list[v].variant);
          a.dx = model.bilinear ? pl.dx : std::floor(pl.dx + 0.5);
          a.dy = model.bilinear ? pl.dy : std::floor(pl.dy + 0.5);
          a.rotation = pl.transform.rotation;
          a.scale = pl.transform.scale;
          a.flip = pl.transform.flip;
        }
        // What each object keeps: all it painted, unless a later object's box meets its
        // own; then its pixels are counted again inside its box.
        size_t kept_count = 0;
        for (size_t t = 0; t < m; ++t) {
          Painted kept = painted[t];
          bool covered = false;
          for (size_t u = t + 1; u < m && !covered; ++u) covered = painted[t].meets(painted[u]);
          if (covered) {
            const uint8_t id = static_cast<uint8_t>(items[t].region + 1);
            kept = Painted{};
            for (int y = painted[t].y0; y <= painted[t].y1; ++y) {
              const uint8_t* row = mask + static_cast<size_t>(y) * W;
              for (int x = painted[t].x0; x <= painted[t].x1; ++x)
                if (row[x] == id) kept.add(x, x + 1, y);
            }
          }
          if (!kept.area) continue;  // nothing visible: no annotation
          Annotation& a = items[kept_count++];
          a = items[t];
          a.area = kept.area;
          a.x = kept.x0;
          a.y = kept.y0;
          a.w = kept.x1 - kept.x0 + 1;
          a.h = kept.y1 - kept.y0 + 1;
        }
        count[i * views + k] = static_cast<uint8_t>(kept_count);
      }
    }
  });
  for (size_t k = 0; k < views; ++k) {
    ViewAnnotations& va = out[k];
    va.items.clear();
    va.first.assign(n + 1, 0);
    for (size_t i = 0; i < n; ++i) {
      va.first[i] = static_cast<uint32_t>(va.items.size());
      va.items.insert(va.items.end(), per[i * views + k].begin(), per[i * views + k].begin() + count[i * views + k]);
    }
    va.first[n] = static_cast<uint32_t>(va.items.size());
  }
}

}  // namespace portalsim
