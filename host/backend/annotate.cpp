#include "backend/annotate.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "backend/reference/stages.h"
#include "base/parallel.h"

namespace portalsim {

namespace {

// Sets bytes [p, p + n) to v with a few overlapping stores: rows of objects' boxes are a
// few dozen bytes, where a call to memset (which GCC makes of any loop of stores) costs more.
inline void fill(uint8_t* p, uint8_t v, int n) {
  using Bytes16 = uint8_t __attribute__((vector_size(16)));
  if (n >= 16) {
    if (n > 64) {
      std::memset(p, v, static_cast<size_t>(n));
      return;
    }
    const Bytes16 w = Bytes16{} + v;
    std::memcpy(p, &w, 16);
    std::memcpy(p + n - 16, &w, 16);
    if (n > 32) {
      std::memcpy(p + 16, &w, 16);
      std::memcpy(p + n - 32, &w, 16);
    }
  } else if (n >= 4) {
    const uint64_t w = 0x0101010101010101ull * v;
    if (n >= 8) {
      std::memcpy(p, &w, 8);
      std::memcpy(p + n - 8, &w, 8);
    } else {
      std::memcpy(p, &w, 4);
      std::memcpy(p + n - 4, &w, 4);
    }
  } else {
    for (int i = 0; i < n; ++i) p[i] = v;
  }
}

// Sets bytes [p, p + n) to cover[i] & v (cover is 0 or 0xff), with overlapping stores
// as fill.
inline void paint_row(uint8_t* p, const uint8_t* cover, uint8_t v, int n) {
  using Bytes16 = uint8_t __attribute__((vector_size(16)));
  if (n >= 16) {
    const Bytes16 w = Bytes16{} + v;
    Bytes16 c;
    for (int o = 0; o < n - 16; o += 16) {
      std::memcpy(&c, cover + o, 16);
      c &= w;
      std::memcpy(p + o, &c, 16);
    }
    std::memcpy(&c, cover + n - 16, 16);
    c &= w;
    std::memcpy(p + n - 16, &c, 16);
  } else if (n >= 8) {
    const uint64_t w = 0x0101010101010101ull * v;
    uint64_t c;
    std::memcpy(&c, cover, 8);
    c &= w;
    std::memcpy(p, &c, 8);
    std::memcpy(&c, cover + n - 8, 8);
    c &= w;
    std::memcpy(p + n - 8, &c, 8);
  } else {
    for (int i = 0; i < n; ++i) p[i] = cover[i] & v;
  }
}

// What one object keeps: its visible pixels' count and box (inclusive).
struct Painted {
  uint32_t area = 0;
  int x0 = INT32_MAX, y0 = INT32_MAX, x1 = -1, y1 = -1;
  void add(int xa, int xb, int y, uint32_t count) {  // `count` pixels within [xa, xb] of row y
    area += count;
    x0 = std::min(x0, xa);
    x1 = std::max(x1, xb);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
};

// One row's painted pixels, gathered pixel by pixel and added to a Painted once.
struct RowSpan {
  int lo = INT32_MAX, hi = -1;
  uint32_t count = 0;
  void add(int x) {
    lo = std::min(lo, x);
    hi = x;
    ++count;
  }
  void to(Painted& p, int y) const {
    if (count) p.add(lo, hi, y, count);
  }
};

// A sprite's covered texels (alpha > 0) as runs [a, b) per row, and their box and count.
struct Runs {
  std::vector<uint32_t> first;  // height + 1: row j's runs are [first[j], first[j + 1])
  std::vector<std::pair<int, int>> runs;
  Painted all;                 // in sprite coordinates
  std::vector<uint8_t> cover;  // all's box, row by row: 0xff where covered, else 0
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
        all.add(a, i - 1, j, static_cast<uint32_t>(i - a));
      }
    }
    first.push_back(static_cast<uint32_t>(runs.size()));
    if (!all.area) return;
    const int w = all.x1 - all.x0 + 1;
    cover.assign(static_cast<size_t>(w) * (all.y1 - all.y0 + 1), 0);
    for (int j = all.y0; j <= all.y1; ++j)
      for (uint32_t k = first[j]; k < first[j + 1]; ++k)
        std::fill_n(cover.begin() + (j - all.y0) * w + (runs[k].first - all.x0), runs[k].second - runs[k].first, 0xff);
  }
};

// One placed object in one view: which pixels it covers (coverage > 0) as the reference's
// composite samples it: at integer placement the texel under the pixel; at bilinear
// placement, and for randomised objects at the sprite point the reference's inverse map
// gives, any of the four texels whose weight, computed as the reference computes it, is
// non-zero. `reach` bounds those pixels (inclusive, within the view; empty when x0 > x1).
class Placement {
 public:
  Placement(const reference::Placed& p, const Runs& runs, const ModelSettings& model, int W, int H)
      : sprite_(p.sprite), runs_(&runs), W_(W), H_(H), bilinear_(model.bilinear), transforms_(model.transforms()) {
    const Image& sp = *p.sprite;
    if (transforms_) {
      map_ = reference::sprite_map(p, bilinear_);
      reach = {0, std::max(0, map_.x0), std::max(0, map_.y0), std::min(W - 1, map_.x1), std::min(H - 1, map_.y1)};
    } else if (!bilinear_) {
      ox_ = p.x0 + static_cast<int>(std::floor(p.dx + 0.5));
      oy_ = p.y0 + static_cast<int>(std::floor(p.dy + 0.5));
      const Painted& a = runs.all;
      if (a.area)
        reach = {0, std::max(0, ox_ + a.x0), std::max(0, oy_ + a.y0), std::min(W - 1, ox_ + a.x1),
                 std::min(H - 1, oy_ + a.y1)};
      whole_ = a.area && ox_ + a.x0 >= 0 && oy_ + a.y0 >= 0 && ox_ + a.x1 < W && oy_ + a.y1 < H;
    } else {
      fx_ = p.x0 + p.dx;
      fy_ = p.y0 + p.dy;
      const int ix = static_cast<int>(std::floor(fx_)), iy = static_cast<int>(std::floor(fy_));
      reach = {0, std::max(0, ix - 1), std::max(0, iy - 1), std::min(W, ix + sp.width + 2) - 1,
               std::min(H, iy + sp.height + 2) - 1};
    }
  }

  Painted reach;

  // Paints id over the pixels it covers, only over 0s when `over_zero` (pixels that objects
  // of higher regions, painted first, own stay theirs), and returns what it painted.
  template <bool over_zero>
  Painted paint(uint8_t id, uint8_t* mask) const {
    if (reach.x0 > reach.x1 || reach.y0 > reach.y1) return {};
    if (transforms_) return paint_mapped<over_zero>(id, mask);
    if (bilinear_) return paint_bilinear<over_zero>(id, mask);
    return paint_runs<over_zero>(id, mask);
  }

 private:
  bool cov(int i, int j) const {
    const Image& sp = *sprite_;
    return i >= 0 && j >= 0 && i < sp.width && j < sp.height && sp.at(i, j, 1);
  }

  template <bool over_zero>
  Painted paint_runs(uint8_t id, uint8_t* mask) const {
    Painted out;
    if (!over_zero && whole_) {  // all of the sprite's coverage, moved: the box is 0 till now
      const Painted& a = runs_->all;
      const int w = a.x1 - a.x0 + 1;
      uint8_t* row = mask + static_cast<size_t>(oy_ + a.y0) * W_ + ox_ + a.x0;
      for (int j = 0; j <= a.y1 - a.y0; ++j) paint_row(row + static_cast<size_t>(j) * W_, &runs_->cover[j * w], id, w);
      out = runs_->all;
      out.x0 += ox_, out.x1 += ox_, out.y0 += oy_, out.y1 += oy_;
      return out;
    }
    for (int j = std::max(runs_->all.y0, -oy_); j <= std::min(runs_->all.y1, H_ - 1 - oy_); ++j) {
      uint8_t* row = mask + static_cast<size_t>(oy_ + j) * W_;
      RowSpan span;
      for (uint32_t k = runs_->first[j]; k < runs_->first[j + 1]; ++k) {
        const int xa = std::max(0, ox_ + runs_->runs[k].first), xb = std::min(W_, ox_ + runs_->runs[k].second);
        if (xa >= xb) continue;
        if constexpr (over_zero) {
          for (int x = xa; x < xb; ++x)
            if (!row[x]) {
              row[x] = id;
              span.add(x);
            }
        } else {
          fill(row + xa, id, xb - xa);
          span.lo = std::min(span.lo, xa);
          span.hi = xb - 1;
          span.count += static_cast<uint32_t>(xb - xa);
        }
      }
      span.to(out, oy_ + j);
    }
    return out;
  }

  template <bool over_zero>
  Painted paint_mapped(uint8_t id, uint8_t* mask) const {
    Painted out;
    for (int y = reach.y0; y <= reach.y1; ++y) {
      uint8_t* row = mask + static_cast<size_t>(y) * W_;
      RowSpan span;
      for (int x = reach.x0; x <= reach.x1; ++x) {
        if (over_zero && row[x]) continue;
        double sx, sy;
        map_.at(x, y, sx, sy);
        const int i = static_cast<int>(std::floor(sx)), j = static_cast<int>(std::floor(sy));
        const bool t = sx - i > 0, ty = sy - j > 0;
        if (cov(i, j) || (t && cov(i + 1, j)) || (ty && cov(i, j + 1)) || (t && ty && cov(i + 1, j + 1))) {
          row[x] = id;
          span.add(x);
        }
      }
      span.to(out, y);
    }
    return out;
  }

  template <bool over_zero>
  Painted paint_bilinear(uint8_t id, uint8_t* mask) const {
    Painted out;
    const int xs = reach.x0, xe = reach.x1 + 1;
    // Per column, the texel column and whether its right neighbour has weight.
    std::vector<int> i0(static_cast<size_t>(xe - xs));
    std::vector<char> tx(i0.size());
    for (int x = xs; x < xe; ++x) {
      const double sx = x - fx_;
      i0[x - xs] = static_cast<int>(std::floor(sx));
      tx[x - xs] = sx - i0[x - xs] > 0;
    }
    const Image& sp = *sprite_;
    for (int y = reach.y0; y <= reach.y1; ++y) {
      const double sy = y - fy_;
      const int j0 = static_cast<int>(std::floor(sy));
      const bool ty = sy - j0 > 0;
      if (j0 < -1 || j0 >= sp.height) continue;
      uint8_t* row = mask + static_cast<size_t>(y) * W_;
      RowSpan span;
      for (int x = xs; x < xe; ++x) {
        if (over_zero && row[x]) continue;
        const int i = i0[x - xs];
        const bool t = tx[x - xs];
        if (cov(i, j0) || (t && cov(i + 1, j0)) || (ty && cov(i, j0 + 1)) || (t && ty && cov(i + 1, j0 + 1))) {
          row[x] = id;
          span.add(x);
        }
      }
      span.to(out, y);
    }
    return out;
  }

  const Image* sprite_;
  const Runs* runs_;
  int W_, H_;
  bool bilinear_, transforms_;
  reference::SpriteMap map_{};
  int ox_ = 0, oy_ = 0;
  bool whole_ = false;  // integer placement with all of the sprite's coverage inside the view
  double fx_ = 0, fy_ = 0;
};

// Copies the lines of a scratch mask that a box touches into the mask, whole:
// streaming stores write a whole line without reading it first, where a store into part
// of one waits for it to come from memory (the masks are megabytes; each scenario touches
// a few dozen scattered lines). Lines that stick out of the mask are copied in part, by
// plain stores.
class Lines {
 public:
  Lines(uint8_t* mask, const uint8_t* scratch, int W, size_t pixels)
      : mask_(reinterpret_cast<uintptr_t>(mask)),
        scratch_(reinterpret_cast<uintptr_t>(scratch)),
        W_(W),
        pixels_(pixels),
        phase_(mask_ & 63) {}

  // Copies the lines box (inclusive) touches to the mask.
  void copy(int x0, int y0, int x1, int y1) const {
    // Offsets from the start of the line the mask starts in.
    size_t a = static_cast<size_t>(y0) * W_ + x0 + phase_, b = a + (x1 - x0);
    const size_t last = (static_cast<size_t>(y1) * W_ + x1 + phase_) | 63;
    const bool inside = a >= 64 && last < pixels_ + phase_;  // no line sticks out of the mask
    size_t next = 0;                                         // rows may share a line
    for (int y = y0; y <= y1; ++y, a += W_, b += W_) {
      for (size_t line = std::max(a & ~size_t{63}, next); line <= b; line += 64) {
        if (inside || (line >= phase_ && line + 64 <= pixels_ + phase_)) {
          stream(mask_ - phase_ + line, scratch_ - phase_ + line);
        } else {
          const size_t s = std::max(line, phase_) - phase_, e = std::min(line + 64, pixels_ + phase_) - phase_;
          std::memcpy(reinterpret_cast<uint8_t*>(mask_ + s), reinterpret_cast<const uint8_t*>(scratch_ + s), e - s);
        }
      }
      next = (b | 63) + 1;
    }
  }
  // Orders the streaming stores before what follows (other threads' reads).
  static void fence() {
#if defined(__SSE2__)
    _mm_sfence();
#endif
  }

 private:
  static void stream(uintptr_t dst, uintptr_t src) {  // dst 64-byte aligned
#if defined(__SSE2__)
    for (int q = 0; q < 4; ++q)
      _mm_stream_si128(reinterpret_cast<__m128i*>(dst) + q, _mm_loadu_si128(reinterpret_cast<const __m128i*>(src) + q));
#else
    std::memcpy(reinterpret_cast<uint8_t*>(dst), reinterpret_cast<const uint8_t*>(src), 64);
#endif
  }
  uintptr_t mask_, scratch_;
  int W_;
  size_t pixels_, phase_;
};

// Asks for huge pages under [p, p + bytes) before it is first touched: the masks are
// megabytes touched a few lines per page, where each 4 KiB page costs a page walk.
void huge_pages(void* p, size_t bytes) {
#if defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  const uintptr_t a = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1),
                  e = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (e > a) ::madvise(reinterpret_cast<void*>(a), e - a, MADV_HUGEPAGE);  // a hint: failure is harmless
#else
  (void)p, (void)bytes;
#endif
}

bool meets(const Painted& a, const Painted& b) { return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1; }

// Where a sprite that does not move sits for its variant, region and view: the same in
// every scenario.
struct Fixed {
  reference::Placed placed{};
  std::optional<Placement> at;
};

// What a worker writes besides the masks, kept for the next call (fresh, its pages would
// fault in each time): its annotations, and per view the scratch mask that the objects
// are painted into first (zero between uses; see Lines).
struct Work {
  std::vector<Annotation> items;
  std::vector<std::vector<uint8_t>> scratch;
};

// Each view's masks for n scenarios. Masks left by the last batch are cleared where they
// were painted (paint_mask); new ones come zeroed.
void size_masks(const Catalogue& cat, size_t n, std::vector<ViewAnnotations>& out) {
  out.resize(cat.sensors.size());
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& sensor = cat.sensors[k];
    ViewAnnotations& va = out[k];
    const size_t px = sensor.pixels();
    if (va.width == sensor.width && va.height == sensor.height && va.painted.size() * px == va.masks.size() &&
        n * px <= va.masks.capacity()) {
      va.masks.resize(n * px);
      va.painted.resize(n);
    } else {
      va.masks = {};
      va.masks.reserve(n * px);
      huge_pages(va.masks.data(), n * px);
      va.masks.assign(n * px, 0);
      va.painted.assign(n, {});
    }
    va.width = sensor.width;
    va.height = sensor.height;
  }
}

// Where sprites that do not move sit, by view, then body (one subject of each shape), variant
// and region: placed from one scene per body, view and variant that holds the variant in
// every region.
std::vector<std::vector<Fixed>> place_fixed(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model,
                                            const std::vector<int>& shape, const std::vector<std::vector<Runs>>& runs) {
  const size_t V = cat.variant_list.size();
  const int R = cat.region_count();
  std::vector<std::vector<Fixed>> fixed(cat.sensors.size());
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& sensor = cat.sensors[k];
    fixed[k].resize(shape.size() * V * R);
    for (size_t b = 0; b < shape.size(); ++b)
      for (size_t v = 0; v < V; ++v) {
        Scenario every;
        every.subject = shape[b];
        every.objects.fill(static_cast<int16_t>(v));
        const reference::ViewScene vs = reference::view_scene(cat, assets, model, static_cast<int>(k), every, 0);
        size_t p = 0;
        for (int r = 0; r < R; ++r) {
          if (!sensor.sees(r)) continue;
          Fixed& f = fixed[k][(b * V + v) * R + r];
          f.placed = vs.placed[p++];
          f.at.emplace(f.placed, runs[k][v], model, sensor.width, sensor.height);
        }
      }
  }
  return fixed;
}

// Paints the m objects of scenario i (at, by region, lowest first) into the scratch mask scr,
// then into the view's mask, and zeroes scr again. kept gets each object's painted box and area.
void paint_mask(const Placement* const* at, const int* regions, size_t m, Painted* kept, uint8_t* scr, int W,
                size_t pixels, ViewAnnotations& va, size_t i) {
  // Highest region first, so that each object paints only the pixels it keeps and
  // its box and area come from that one pass; one that may reach a pixel an object
  // above it kept paints over 0s only.
  for (size_t t = m; t-- > 0;) {
    bool under = false;
    for (size_t u = t + 1; u < m && !under; ++u) under = kept[u].area && meets(at[t]->reach, kept[u]);
    const uint8_t id = static_cast<uint8_t>(regions[t] + 1);
    kept[t] = under ? at[t]->paint<true>(id, scr) : at[t]->paint<false>(id, scr);
  }
  // The mask's non-zero pixels lie in the boxes painted last time: copying the lines
  // of those (unless a new box holds one) and of the new boxes from the scratch mask
  // clears the old and writes the new.
  ViewAnnotations::Painted& dirty = va.painted[i];
  const Lines lines(va.masks.data() + i * pixels, scr, W, pixels);
  for (int b = 0; b < dirty.count; ++b) {
    const auto& [x0, y0, x1, y1] = dirty.box[b];
    bool held = false;
    for (size_t t = 0; t < m && !held; ++t)
      held = kept[t].area && kept[t].x0 <= x0 && kept[t].y0 <= y0 && x1 <= kept[t].x1 && y1 <= kept[t].y1;
    if (!held) lines.copy(x0, y0, x1, y1);
  }
  dirty.count = 0;
  for (size_t t = 0; t < m; ++t)
    if (const Painted& d = kept[t]; d.area) {
      lines.copy(d.x0, d.y0, d.x1, d.y1);
      dirty.box[dirty.count++] = {static_cast<int16_t>(d.x0), static_cast<int16_t>(d.y0), static_cast<int16_t>(d.x1),
                                  static_cast<int16_t>(d.y1)};
    }
  for (size_t t = 0; t < m; ++t)
    for (int y = kept[t].y0; y <= kept[t].y1; ++y)
      fill(scr + static_cast<size_t>(y) * W + kept[t].x0, 0, kept[t].x1 - kept[t].x0 + 1);
}

// Scenario i's annotations of one view, one per visible object; returns how many.
size_t append_annotations(const Catalogue& cat, const ModelSettings& model, const reference::Placed* const* placed,
                          const int* regions, const Painted* kept, size_t m, size_t i, std::vector<Annotation>& mine) {
  size_t kept_count = 0;
  for (size_t t = 0; t < m; ++t) {
    if (!kept[t].area) continue;  // nothing visible: no annotation
    const reference::Placed& pl = *placed[t];
    const VariantRef& v = cat.variant_list[pl.variant];
    Annotation& an = mine.emplace_back();
    an.scenario = static_cast<uint32_t>(i);
    an.region = static_cast<uint8_t>(regions[t]);
    an.object = static_cast<int16_t>(v.object);
    an.drawing = static_cast<int16_t>(v.variant);
    an.x = kept[t].x0;
    an.y = kept[t].y0;
    an.w = kept[t].x1 - kept[t].x0 + 1;
    an.h = kept[t].y1 - kept[t].y0 + 1;
    an.area = kept[t].area;
    an.dx = model.bilinear ? pl.dx : std::floor(pl.dx + 0.5);
    an.dy = model.bilinear ? pl.dy : std::floor(pl.dy + 0.5);
    an.rotation = pl.transform.rotation;
    an.scale = pl.transform.scale;
    an.flip = pl.transform.flip;
    ++kept_count;
  }
  return kept_count;
}

// The workers' lists (by first scenario), joined into each view's items by scenario.
void join_work(std::vector<std::pair<size_t, Work>>& done, const std::vector<uint8_t>& count, size_t n,
               std::vector<ViewAnnotations>& out) {
  const size_t views = out.size();
  std::sort(done.begin(), done.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (ViewAnnotations& va : out) {
    va.items.clear();
    va.first.assign(n + 1, 0);
  }
  size_t part = 0, at = 0;
  for (size_t i = 0; i < n; ++i) {
    if (part + 1 < done.size() && done[part + 1].first == i) ++part, at = 0;
    for (size_t k = 0; k < views; ++k) {
      ViewAnnotations& va = out[k];
      va.first[i] = static_cast<uint32_t>(va.items.size());
      const auto from = done[part].second.items.begin() + static_cast<ptrdiff_t>(at);
      va.items.insert(va.items.end(), from, from + count[i * views + k]);
      at += count[i * views + k];
    }
  }
  for (ViewAnnotations& va : out) va.first[n] = static_cast<uint32_t>(va.items.size());
}

}  // namespace

// Each view's sprites' covered texels (by variant), where unmoved sprites sit (built on
// the first batch that has them), and the workers' buffers between batches.
struct Annotator::Kept {
  const Catalogue& cat;
  const AssetSet& assets;
  std::vector<std::vector<Runs>> runs;
  // Subjects whose places are the same (Sensor::subject_dx and subject_dy in every view) share a body:
  // body[subject] indexes `shape`, which names one such subject.
  std::vector<int> body, shape;
  std::vector<std::vector<Fixed>> fixed;  // per view, (body * variants + variant) * regions + region
  std::vector<Work> spare;
};

Annotator::Annotator(const Catalogue& cat, const AssetSet& assets) : kept_(new Kept{cat, assets, {}, {}, {}, {}, {}}) {
  for (size_t j = 0; j < cat.subjects.size(); ++j) {
    size_t b = 0;
    const auto same = [&](int other) {
      for (const Sensor& s : cat.sensors)
        if (s.subject_dy[j] != s.subject_dy[other] || s.subject_dx[j] != s.subject_dx[other]) return false;
      return true;
    };
    while (b < kept_->shape.size() && !same(kept_->shape[b])) ++b;
    if (b == kept_->shape.size()) kept_->shape.push_back(static_cast<int>(j));
    kept_->body.push_back(static_cast<int>(b));
  }
  kept_->runs.resize(cat.sensors.size());
  for (size_t k = 0; k < cat.sensors.size(); ++k)
    for (size_t v = 0; v < cat.variant_list.size(); ++v)
      kept_->runs[k].emplace_back(assets.sprite(cat.sensors[k], static_cast<int>(v)));
}

Annotator::~Annotator() = default;

void annotate(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model, const SceneBatch& batch,
              std::vector<ViewAnnotations>& out, unsigned threads) {
  Annotator(cat, assets)(model, batch, out, threads);
}

void Annotator::operator()(const ModelSettings& model, const SceneBatch& batch, std::vector<ViewAnnotations>& out,
                           unsigned threads) {
  const Catalogue& cat = kept_->cat;
  const AssetSet& assets = kept_->assets;
  const std::vector<std::vector<Runs>>& runs = kept_->runs;
  const size_t n = batch.size(), views = cat.sensors.size();
  size_masks(cat, n, out);
  // Sprites that do not move sit where their variant, region, view and subject's body put
  // them, the same in every scenario and for any model that does not move them: placed once.
  std::vector<std::vector<Fixed>>& fixed = kept_->fixed;
  const std::vector<int>& body = kept_->body;
  const size_t V = cat.variant_list.size();
  const int R = cat.region_count();
  const bool moves = model.moves_sprites();
  if (!moves && fixed.empty()) fixed = place_fixed(cat, assets, model, kept_->shape, runs);
  // Each worker's annotations in a list of its own, by scenario, then view (count says how
  // many each image has), joined below in the order of the workers' first scenarios.
  std::vector<uint8_t> count(n * views, 0);
  std::vector<Work>& spare = kept_->spare;
  std::vector<std::pair<size_t, Work>> done;  // by first scenario
  std::mutex work_mutex;
  // Below this many scenarios a batch is done before threads would have started.
  constexpr size_t kThreadedScenarios = 256;
  parallel_for(n, n >= kThreadedScenarios ? threads : 1, [&](size_t lo, size_t hi) {
    Work work;
    {
      const std::lock_guard<std::mutex> lock(work_mutex);
      if (!spare.empty()) {
        work = std::move(spare.back());
        spare.pop_back();
      }
    }
    std::vector<Annotation>& mine = work.items;
    mine.clear();
    std::vector<std::vector<uint8_t>>& scratch = work.scratch;
    scratch.resize(views);
    for (size_t k = 0; k < views; ++k)
      if (scratch[k].size() != cat.sensors[k].pixels()) scratch[k].assign(cat.sensors[k].pixels(), 0);
    std::vector<reference::Placed> moved;  // this view's objects, where sprites move
    std::vector<Placement> moved_at;
    std::array<const reference::Placed*, kMaxRegions> placed;
    std::array<const Placement*, kMaxRegions> at;
    std::array<int, kMaxRegions> regions;
    std::array<Painted, kMaxRegions> kept;
    for (size_t i = lo; i < hi; ++i) {
      const Scenario s = batch.at(i);
      for (size_t k = 0; k < views; ++k) {
        const Sensor& sensor = cat.sensors[k];
        const int W = sensor.width;
        uint8_t* scr = scratch[k].data();
        size_t m = 0;
        if (moves) {
          moved = reference::view_scene(cat, assets, model, static_cast<int>(k), s, batch.index_of(i)).placed;
          moved_at.clear();
          for (const reference::Placed& pl : moved)
            moved_at.emplace_back(pl, runs[k][pl.variant], model, W, sensor.height);
        }
        for (int r = 0; r < R; ++r) {
          const int16_t v = s.objects[r];
          if (v == kNoObject || !sensor.sees(r)) continue;
          if (moves) {
            placed[m] = &moved[m];
            at[m] = &moved_at[m];
          } else {
            const Fixed& f = fixed[k][(static_cast<size_t>(body[s.subject]) * V + v) * R + r];
            placed[m] = &f.placed;
            at[m] = &*f.at;
          }
          regions[m++] = r;
        }
        paint_mask(at.data(), regions.data(), m, kept.data(), scr, W, sensor.pixels(), out[k], i);
        count[i * views + k] = static_cast<uint8_t>(
            append_annotations(cat, model, placed.data(), regions.data(), kept.data(), m, i, mine));
      }
    }
    Lines::fence();
    const std::lock_guard<std::mutex> lock(work_mutex);
    done.emplace_back(lo, std::move(work));
  });
  join_work(done, count, n, out);
  for (auto& d : done) spare.push_back(std::move(d.second));
}

}  // namespace portalsim
