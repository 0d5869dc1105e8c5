// The CPU reference: the sensor model written as plainly as possible, in double
// precision, one pixel at a time. It shares nothing with kernels/ except the random
// generator (scene/philox.h) and the catalogue's data; tests hold the kernels to it.
#include <algorithm>
#include <cmath>

#include "backend/backend.h"
#include "scene/philox.h"

namespace portalsim {

namespace {

constexpr double kTwoPi = 6.283185307179586;

class ReferenceBackend final : public Backend {
 public:
  ReferenceBackend(const Catalogue& cat, const AssetSet& assets) : cat_(cat), assets_(assets) {}
  std::string name() const override { return "reference"; }

  void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) override {
    const ImagesConfig& ic = cat_.images;
    const size_t n = batch.size();
    prepare_output(out, cat_, plan, n);
    const size_t mmw_px = static_cast<size_t>(ic.mmw_width) * ic.mmw_height;
    const size_t ir_px = static_cast<size_t>(ic.ir_width) * ic.ir_height;

    std::vector<uint8_t> upper(mmw_px), lower(mmw_px), ir(ir_px);
    for (size_t i = 0; i < n; ++i) {
      const Scenario s = batch.at(i);
      const uint64_t index = batch.first_index + i;
      if (plan.renders_mmw()) {
        render(s, index, plan.model, 0, upper);
        render(s, index, plan.model, 1, lower);
        if (plan.mmw_images) {
          std::copy(upper.begin(), upper.end(), out.upper.begin() + i * mmw_px);
          std::copy(lower.begin(), lower.end(), out.lower.begin() + i * mmw_px);
        }
        if (plan.features) pool(upper, lower, out.layout, &out.features[i * out.layout.image_features()]);
      }
      if (plan.ir_image) {
        render(s, index, plan.model, 2, ir);
        std::copy(ir.begin(), ir.end(), out.ir.begin() + i * ir_px);
      }
      if (plan.metal) metal(s, index, plan.model, &out.metal[i * kZones]);
    }
  }

 private:
  // view: 0 MMW upper, 1 MMW lower, 2 IR.
  void render(const Scenario& s, uint64_t index, const ModelSettings& m, int view, std::vector<uint8_t>& img) const {
    const ImagesConfig& ic = cat_.images;
    const Image& base = assets_.bases[s.subject][view];
    const int W = base.width, H = base.height;
    std::vector<double> value(static_cast<size_t>(W) * H);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) value[y * W + x] = base.at(x, y);

    struct Placed {
      const Image* sprite;
      int x0, y0;     // centred in the region: where the noise tile goes
      double dx, dy;  // the placement jitter
    };
    std::vector<Placed> placed;
    const double scale_x = view < 2 ? 1.0 : double(ic.ir_width) / ic.mmw_width;
    const double scale_y = view < 2 ? 1.0 : double(ic.ir_height) / (2.0 * ic.mmw_height);
    for (int r = 0; r < kRegions; ++r) {
      const int16_t v = s.objects[r];
      if (v == kNoObject) continue;
      const Region& reg = cat_.regions[r];
      if (view < 2 && static_cast<int>(reg.view) != view) continue;
      const Image& sp = view < 2 ? assets_.mmw_sprites[v] : assets_.ir_sprites[v];
      const Rect& rect = view < 2 ? reg.mmw : reg.ir;
      const int x0 = rect.x + static_cast<int>(std::floor((rect.w - sp.width) / 2.0));
      const int y0 = rect.y + static_cast<int>(std::floor((rect.h - sp.height) / 2.0));
      double dx = 0, dy = 0;
      if (m.jitter > 0) {
        const Philox4 q = draw(m.seed, index, kStreamJitter, static_cast<uint32_t>(r));
        dx = m.jitter * scale_x * (2.0 * uniform24(q[0]) - 1.0);
        dy = m.jitter * scale_y * (2.0 * uniform24(q[1]) - 1.0);
      }
      placed.push_back({&sp, x0, y0, dx, dy});
    }

    // Composite (thesis algorithm step 8): objects in region order over the base.
    for (const Placed& p : placed) {
      const Image& sp = *p.sprite;
      if (!m.bilinear) {
        const int ox = p.x0 + static_cast<int>(std::floor(p.dx + 0.5));
        const int oy = p.y0 + static_cast<int>(std::floor(p.dy + 0.5));
        for (int sy = 0; sy < sp.height; ++sy)
          for (int sx = 0; sx < sp.width; ++sx) {
            const int x = ox + sx, y = oy + sy;
            if (x < 0 || y < 0 || x >= W || y >= H) continue;
            const double a = ic.alpha * sp.at(sx, sy, 1) / 255.0;
            double& v = value[y * W + x];
            v = a * sp.at(sx, sy, 0) + (1.0 - a) * v;
          }
        continue;
      }
      // Sub-pixel: the sprite's premultiplied value and coverage, sampled bilinearly.
      const double fx = p.x0 + p.dx, fy = p.y0 + p.dy;
      const auto texel = [&](int i, int j, double& pv, double& c) {
        if (i < 0 || j < 0 || i >= sp.width || j >= sp.height) return;
        const double cov = sp.at(i, j, 1) / 255.0;
        pv = cov * sp.at(i, j, 0);
        c = cov;
      };
      for (int y = std::max(0, static_cast<int>(std::floor(fy)) - 1);
           y < std::min(H, static_cast<int>(fy) + sp.height + 2); ++y)
        for (int x = std::max(0, static_cast<int>(std::floor(fx)) - 1);
             x < std::min(W, static_cast<int>(fx) + sp.width + 2); ++x) {
          const double sx = x - fx, sy = y - fy;
          const int i0 = static_cast<int>(std::floor(sx)), j0 = static_cast<int>(std::floor(sy));
          const double tx = sx - i0, ty = sy - j0;
          double pv = 0, c = 0;
          for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
              double tpv = 0, tc = 0;
              texel(i0 + i, j0 + j, tpv, tc);
              const double w = (i ? tx : 1 - tx) * (j ? ty : 1 - ty);
              pv += w * tpv;
              c += w * tc;
            }
          if (c == 0) continue;
          double& v = value[y * W + x];
          v = (1.0 - ic.alpha * c) * v + ic.alpha * pv;
        }
    }

    // Noise (thesis 4.2): the scenario's pattern, centred on every object in MMW views.
    if (view < 2 && m.pattern_noise && !placed.empty()) {
      const uint32_t k =
          below(draw(m.seed, index, kStreamNoisePattern, 0)[0], static_cast<uint32_t>(assets_.noise.size()));
      const Image& tile = assets_.noise[k];
      const double gain = cat_.noise[k].gain;
      for (const Placed& p : placed) {
        const int tx0 =
            p.x0 + static_cast<int>(std::floor(p.sprite->width / 2.0)) - static_cast<int>(std::floor(tile.width / 2.0));
        const int ty0 = p.y0 + static_cast<int>(std::floor(p.sprite->height / 2.0)) -
                        static_cast<int>(std::floor(tile.height / 2.0));
        for (int ty = 0; ty < tile.height; ++ty)
          for (int tx = 0; tx < tile.width; ++tx) {
            const int x = tx0 + tx, y = ty0 + ty;
            if (x < 0 || y < 0 || x >= W || y >= H) continue;
            value[y * W + x] += gain * (tile.at(tx, ty) - 128.0);
          }
      }
    }

    // Per-pixel sensor noise: Box-Muller over the counter generator, a pair per draw.
    if (m.pixel_sigma > 0) {
      for (int p = 0; p < W * H; ++p) {
        const Philox4 r =
            draw(m.seed, index, kStreamPixelNoise, (static_cast<uint32_t>(view) << 28) | static_cast<uint32_t>(p / 2));
        const double u1 = 1.0 - uniform24(r[0]), u2 = uniform24(r[1]);
        const double rad = std::sqrt(-2.0 * std::log(u1));
        const double g = (p % 2 == 0) ? rad * std::cos(kTwoPi * u2) : rad * std::sin(kTwoPi * u2);
        value[p] += m.pixel_sigma * g;
      }
    }

    img.resize(value.size());
    for (size_t p = 0; p < value.size(); ++p)
      img[p] = static_cast<uint8_t>(std::clamp(std::floor(value[p] + 0.5), 0.0, 255.0));
  }

  // Block means of both MMW views, then the mean of each region's rectangle (thesis 5.6).
  void pool(const std::vector<uint8_t>& upper, const std::vector<uint8_t>& lower, const FeatureLayout& f,
            float* row) const {
    const int W = cat_.images.mmw_width, H = cat_.images.mmw_height, n = f.block;
    int k = 0;
    for (const std::vector<uint8_t>* img : {&upper, &lower})
      for (int by = 0; by < f.blocks_y; ++by)
        for (int bx = 0; bx < f.blocks_x; ++bx) {
          double sum = 0;
          int count = 0;
          for (int y = by * n; y < std::min(H, (by + 1) * n); ++y)
            for (int x = bx * n; x < std::min(W, (bx + 1) * n); ++x) {
              sum += (*img)[y * W + x];
              ++count;
            }
          row[k++] = static_cast<float>(sum / count);
        }
    for (const Region& reg : cat_.regions) {
      const std::vector<uint8_t>& img = reg.view == View::upper ? upper : lower;
      double sum = 0;
      for (int y = reg.mmw.y; y < reg.mmw.y + reg.mmw.h; ++y)
        for (int x = reg.mmw.x; x < reg.mmw.x + reg.mmw.w; ++x) sum += img[y * W + x];
      row[k++] = static_cast<float>(sum / (static_cast<double>(reg.mmw.w) * reg.mmw.h));
    }
  }

  // Metal zones (thesis algorithm step 2): base minus every object's influence, clamped.
  void metal(const Scenario& s, uint64_t index, const ModelSettings& m, uint8_t* zones) const {
    for (int z = 0; z < kZones; ++z) {
      int sum = 0;
      for (int r = 0; r < kRegions; ++r)
        if (s.objects[r] != kNoObject) sum += cat_.influence[cat_.object_of(s.objects[r]).metal][r][z];
      int value = cat_.subjects[s.subject].base_zones[z] - sum;
      if (m.metal_noise > 0 && sum > 0) {
        const Philox4 r = draw(m.seed, index, kStreamMetalNoise, static_cast<uint32_t>(z));
        value += static_cast<int>(below(r[0], m.metal_noise + 1)) - static_cast<int>(below(r[1], m.metal_noise + 1));
      }
      zones[z] = static_cast<uint8_t>(std::clamp(value, 1, 200));
    }
  }

  const Catalogue& cat_;
  const AssetSet& assets_;
};

}  // namespace

std::unique_ptr<Backend> make_reference_backend(const Catalogue& cat, const AssetSet& assets) {
  return std::make_unique<ReferenceBackend>(cat, assets);
}

}  // namespace portalsim
