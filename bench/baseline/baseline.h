// The baselines of issue 14: plain C++ loops (OpenMP over scenarios, inner loops that
// g++ vectorises at -O3 -march=native) doing the kernels' work with output bit-identical
// to the standard tier. A kernel path slower than its baseline is a defect. They share
// no code with kernels/ or with the reference (host/backend/reference/).
#pragma once
#include <array>
#include <vector>

#include "assets/assets.h"
#include "backend/backend.h"

namespace portalsim::baseline {

// Every camera view's images for `batch`, as the standard tier renders them: fp32,
// integer placement without jitter, pattern noise and per-pixel sensor noise
// (sigma = model.pixel_sigma) with the kernels' polynomial Box-Muller transform.
// `out` is sized as prepare_output does for a plan that keeps every view.
void render_images(const Catalogue& cat, const AssetSet& assets, const SceneBatch& batch, const ModelSettings& model,
                   BatchOutput& out);

// Features-only rows (block and region means of the pooled views) for the standard tier
// without pixel noise: portalsim's sparse table algorithm as plain loops. Tables are made
// once (constructor); run() is the per-batch work. `out.features` is sized as
// prepare_output does for a features-only plan.
class SparseFeatures {
 public:
  SparseFeatures(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model);
  void run(const SceneBatch& batch, BatchOutput& out) const;

 private:
  // Where one variant in one region changes pixels, and its deltas per (subject, pattern):
  // block sums (bw x bh) then the region sums.
  struct Footprint {
    const Image* sprite = nullptr;
    int sx = 0, sy = 0, tx = 0, ty = 0;  // sprite and noise-tile corners
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // changed pixels lie in [x0, x1) x [y0, y1)
    int bx0 = 0, by0 = 0, bw = 0, bh = 0;
    std::vector<int32_t> deltas;
  };
  int32_t* delta_of(Footprint& f, int s, int p) {
    return f.deltas.data() + (s * patterns_ + p) * (f.bw * f.bh + layout_.regions);
  }
  const int32_t* delta_of(const Footprint& f, int s, int p) const {
    return f.deltas.data() + (s * patterns_ + p) * (f.bw * f.bh + layout_.regions);
  }
  uint8_t pixel(const Footprint* const* fps, int count, uint8_t base, int x, int y, int pattern) const;
  int region_pixels(int r) const;
  bool in_region(int r, int x, int y) const;

  const Catalogue& cat_;
  const AssetSet& assets_;
  ModelSettings model_;
  FeatureLayout layout_;
  int W_ = 0, H_ = 0, tile_ = 0, patterns_ = 1;
  float alpha_ = 0;
  std::array<int, kMaxRegions> slot_{};  // the pooled view each region lies in
  std::vector<int> count_;               // pixels per block
  std::vector<uint32_t> base_sums_;      // per subject, a row of integer sums
  std::vector<float> base_means_;        // per subject, a features row
  std::vector<Footprint> prints_;        // per (variant, region)
};

}  // namespace portalsim::baseline
