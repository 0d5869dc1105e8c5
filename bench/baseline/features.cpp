#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "baseline.h"
#include "philox_words.h"

namespace portalsim::baseline {

namespace {

float mean_of(uint32_t sum, int count) {
  const uint32_t c = static_cast<uint32_t>(count), q = sum / c, r = sum % c;
  return std::clamp(static_cast<float>(q) + static_cast<float>(r) / static_cast<float>(count), 0.0f, 255.0f);
}

uint8_t to_pixel(float v) { return static_cast<uint8_t>(std::clamp(std::floor(v + 0.5f), 0.0f, 255.0f)); }

}  // namespace

SparseFeatures::SparseFeatures(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model)
    : cat_(cat), assets_(assets), model_(model), layout_(FeatureLayout::of(cat, model.block)) {
  if (model.pixel_sigma > 0 || model.moves_sprites())
    throw std::invalid_argument("the features baseline is the sparse path: no pixel noise, no jitter");
  if (!layout_.uniform) throw std::invalid_argument("the features baseline takes pooled views of one size");
  const Sensor& first = cat.sensors[layout_.pooled.at(0)];
  W_ = first.width;
  H_ = first.height;
  const int block = layout_.block, bx = layout_.grids.at(0).blocks_x, by = layout_.grids.at(0).blocks_y,
            per_view = bx * by;
  alpha_ = static_cast<float>(cat.images.alpha);
  tile_ = cat.images.noise_size;
  patterns_ = model.pattern_noise ? static_cast<int>(cat.noise.size()) : 1;
  for (int r = 0; r < layout_.regions; ++r) {
    slot_[r] = 0;
    for (size_t s = 0; s < layout_.pooled.size(); ++s)
      if (cat.sensors[layout_.pooled[s]].sees(r)) {
        slot_[r] = static_cast<int>(s);
        break;
      }
  }
  count_.resize(per_view);
  for (int b = 0; b < per_view; ++b) {
    const int x0 = (b % bx) * block, y0 = (b / bx) * block;
    count_[b] = (std::min(x0 + block, W_) - x0) * (std::min(y0 + block, H_) - y0);
  }

  // Per subject: base sums and means, laid out as a features row.
  const int row_len = layout_.image_features(), S = static_cast<int>(cat.subjects.size());
  base_sums_.assign(static_cast<size_t>(S) * row_len, 0);
  base_means_.assign(static_cast<size_t>(S) * row_len, 0.0f);
  for (int s = 0; s < S; ++s) {
    uint32_t* sums = &base_sums_[static_cast<size_t>(s) * row_len];
    for (size_t slot = 0; slot < layout_.pooled.size(); ++slot) {
      const Image& img = assets.bases[s][layout_.pooled[slot]];
      for (int y = 0; y < H_; ++y)
        for (int x = 0; x < W_; ++x) sums[slot * per_view + (y / block) * bx + x / block] += img.pixels[y * W_ + x];
    }
    for (int r = 0; r < layout_.regions; ++r) {
      const Image& img = assets.bases[s][layout_.pooled[slot_[r]]];
      const Rect& rc = cat.sensors[layout_.pooled[slot_[r]]].rects[r];
      for (int y = rc.y; y < rc.y + rc.h; ++y)
        for (int x = rc.x; x < rc.x + rc.w; ++x) sums[layout_.block_features() + r] += img.pixels[y * W_ + x];
    }
    for (int f = 0; f < row_len; ++f)
      base_means_[static_cast<size_t>(s) * row_len + f] = mean_of(
          sums[f], f < layout_.block_features() ? count_[f % per_view] : region_pixels(f - layout_.block_features()));
  }

  // Per (variant, region): where the object changes pixels, and per (subject, pattern)
  // the sums of (pixel - base) over each block and region it touches.
  const int V = static_cast<int>(cat.variant_list.size());
  prints_.resize(static_cast<size_t>(V) * layout_.regions);
  for (int v = 0; v < V; ++v)
    for (int r = 0; r < layout_.regions; ++r) {
      Footprint& fp = prints_[static_cast<size_t>(v) * layout_.regions + r];
      const Sensor& in = cat.sensors[layout_.pooled[slot_[r]]];
      const Image& sp = assets.sprite(in, v);
      const Rect& rc = in.rects[r];
      fp.sprite = &sp;
      fp.sx = rc.x + ((rc.w - sp.width) >> 1);
      fp.sy = rc.y + ((rc.h - sp.height) >> 1);
      fp.tx = fp.sx + (sp.width >> 1) - (tile_ >> 1);
      fp.ty = fp.sy + (sp.height >> 1) - (tile_ >> 1);
      fp.x0 = fp.sx, fp.y0 = fp.sy, fp.x1 = fp.sx + sp.width, fp.y1 = fp.sy + sp.height;
      if (model.pattern_noise) {
        fp.x0 = std::min(fp.x0, fp.tx), fp.y0 = std::min(fp.y0, fp.ty);
        fp.x1 = std::max(fp.x1, fp.tx + tile_), fp.y1 = std::max(fp.y1, fp.ty + tile_);
      }
      fp.x0 = std::clamp(fp.x0, 0, W_), fp.x1 = std::clamp(fp.x1, fp.x0, W_);
      fp.y0 = std::clamp(fp.y0, 0, H_), fp.y1 = std::clamp(fp.y1, fp.y0, H_);
      fp.bx0 = fp.x0 / block, fp.by0 = fp.y0 / block;
      fp.bw = fp.x1 > fp.x0 ? (fp.x1 - 1) / block - fp.bx0 + 1 : 0;
      fp.bh = fp.y1 > fp.y0 ? (fp.y1 - 1) / block - fp.by0 + 1 : 0;
      fp.deltas.assign(static_cast<size_t>(S) * patterns_ * (fp.bw * fp.bh + layout_.regions), 0);
      for (int s = 0; s < S; ++s)
        for (int p = 0; p < patterns_; ++p) {
          int32_t* d = delta_of(fp, s, p);
          const uint8_t* base = assets.bases[s][layout_.pooled[slot_[r]]].pixels.data();
          for (int y = fp.y0; y < fp.y1; ++y)
            for (int x = fp.x0; x < fp.x1; ++x) {
              const Footprint* one = &fp;
              const int diff = static_cast<int>(pixel(&one, 1, base[y * W_ + x], x, y, p)) - base[y * W_ + x];
              if (diff == 0) continue;
              d[(y / block - fp.by0) * fp.bw + x / block - fp.bx0] += diff;
              for (int q = 0; q < layout_.regions; ++q)
                if (slot_[q] == slot_[r] && in_region(q, x, y)) d[fp.bw * fp.bh + q] += diff;
            }
        }
    }
}

int SparseFeatures::region_pixels(int r) const {
  const Rect& rc = cat_.sensors[layout_.pooled[slot_[r]]].rects[r];
  return rc.w * rc.h;
}

bool SparseFeatures::in_region(int r, int x, int y) const {
  const Rect& rc = cat_.sensors[layout_.pooled[slot_[r]]].rects[r];
  return x >= rc.x && y >= rc.y && x < rc.x + rc.w && y < rc.y + rc.h;
}

// The pixel at (x, y) with objects fps[0..count) over `base`, as the standard tier renders it.
uint8_t SparseFeatures::pixel(const Footprint* const* fps, int count, uint8_t base, int x, int y, int pattern) const {
  float v = base;
  for (int k = 0; k < count; ++k) {
    const Footprint& f = *fps[k];
    const int sx = x - f.sx, sy = y - f.sy;
    if (sx < 0 || sy < 0 || sx >= f.sprite->width || sy >= f.sprite->height) continue;
    const uint8_t* px = f.sprite->pixels.data() + (static_cast<size_t>(sy) * f.sprite->width + sx) * 2;
    const float a = alpha_ * static_cast<float>(px[1]) / 255.0f;
    v = std::fma(a, static_cast<float>(px[0]) - v, v);
  }
  if (model_.pattern_noise) {
    float n = 0.0f;
    const Image& tile = assets_.noise[pattern];
    for (int k = 0; k < count; ++k) {
      const int tx = x - fps[k]->tx, ty = y - fps[k]->ty;
      if (tx >= 0 && ty >= 0 && tx < tile_ && ty < tile_)
        n = n + (static_cast<float>(tile.pixels[ty * tile_ + tx]) - 128.0f);
    }
    v = v + static_cast<float>(cat_.noise[pattern].gain) * n;
  }
  return to_pixel(v);
}

void SparseFeatures::run(const SceneBatch& batch, BatchOutput& out) const {
  const size_t n = batch.size();
  const int row_len = layout_.image_features(), bx = layout_.grids.at(0).blocks_x, block = layout_.block;
  const int per_view = layout_.grids.at(0).blocks(), npooled = static_cast<int>(layout_.pooled.size());
#pragma omp parallel
  {
    std::vector<int32_t> acc(per_view);
    std::vector<uint32_t> block_stamp(per_view, 0), pixel_stamp(static_cast<size_t>(W_) * H_, 0);
    uint32_t stamp = 0;
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; ++i) {
      const int s = batch.subject[i];
      const int16_t* objects = &batch.objects[i * layout_.regions];
      float* row = out.features.data() + i * row_len;
      std::memcpy(row, &base_means_[static_cast<size_t>(s) * row_len], row_len * sizeof(float));
      int pattern = 0;
      if (model_.pattern_noise) {
        uint32_t r0, r1;
        philox_words(0, PS_STREAM_NOISE_PATTERN, batch.first_index + i, model_.seed, r0, r1);
        pattern = static_cast<int>((static_cast<uint64_t>(r0) * static_cast<uint32_t>(patterns_)) >> 32);
      }
      const uint32_t* bsum = &base_sums_[static_cast<size_t>(s) * row_len];
      int32_t reg[kMaxRegions];
      for (int r = 0; r < layout_.regions; ++r) reg[r] = static_cast<int32_t>(bsum[layout_.block_features() + r]);
      bool touched = false;
      for (int slot = 0; slot < npooled; ++slot) {
        const Footprint* fps[kMaxRegions];
        int cnt = 0;
        for (int r = 0; r < layout_.regions; ++r)
          if (objects[r] >= 0 && slot_[r] == slot)
            fps[cnt++] = &prints_[static_cast<size_t>(objects[r]) * layout_.regions + r];
        if (cnt == 0) continue;
        touched = true;
        ++stamp;
        for (int k = 0; k < cnt; ++k) {
          const Footprint& f = *fps[k];
          const int32_t* d = delta_of(f, s, pattern);
          for (int y = 0; y < f.bh; ++y)
            for (int x = 0; x < f.bw; ++x) {
              const int b = (f.by0 + y) * bx + f.bx0 + x;
              if (block_stamp[b] != stamp) {
                block_stamp[b] = stamp;
                acc[b] = static_cast<int32_t>(bsum[slot * per_view + b]);
              }
              acc[b] += d[y * f.bw + x];
            }
          for (int r = 0; r < layout_.regions; ++r) reg[r] += d[f.bw * f.bh + r];
        }
        // Where footprints overlap the single-object deltas are wrong: replace their sum
        // by the pixel rendered with every object, once per pixel.
        const uint8_t* base = assets_.bases[s][layout_.pooled[slot]].pixels.data();
        for (int a = 0; a < cnt; ++a)
          for (int b = a + 1; b < cnt; ++b) {
            const int x0 = std::max(fps[a]->x0, fps[b]->x0), x1 = std::min(fps[a]->x1, fps[b]->x1);
            const int y0 = std::max(fps[a]->y0, fps[b]->y0), y1 = std::min(fps[a]->y1, fps[b]->y1);
            for (int y = y0; y < y1; ++y)
              for (int x = x0; x < x1; ++x) {
                uint32_t& seen = pixel_stamp[static_cast<size_t>(y) * W_ + x];
                if (seen == stamp) continue;
                seen = stamp;
                const uint8_t bp = base[y * W_ + x];
                int singles = 0;
                for (int k = 0; k < cnt; ++k) {
                  const Footprint& f = *fps[k];
                  if (x < f.x0 || y < f.y0 || x >= f.x1 || y >= f.y1) continue;
                  const Footprint* one = &f;
                  singles += static_cast<int>(pixel(&one, 1, bp, x, y, pattern)) - bp;
                }
                const int corr = static_cast<int>(pixel(fps, cnt, bp, x, y, pattern)) - bp - singles;
                if (corr == 0) continue;
                acc[(y / block) * bx + x / block] += corr;
                for (int r = 0; r < layout_.regions; ++r)
                  if (slot_[r] == slot && in_region(r, x, y)) reg[r] += corr;
              }
          }
        for (int b = 0; b < per_view; ++b)
          if (block_stamp[b] == stamp) row[slot * per_view + b] = mean_of(static_cast<uint32_t>(acc[b]), count_[b]);
      }
      if (touched)
        for (int r = 0; r < layout_.regions; ++r)
          row[layout_.block_features() + r] = mean_of(static_cast<uint32_t>(reg[r]), region_pixels(r));
    }
  }
}

}  // namespace portalsim::baseline
