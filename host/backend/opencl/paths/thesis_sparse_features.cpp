// The thesis model's features-only path (kernels/pool_sparse.cl): each subject's base
// features and each object footprint's change to them, tabulated once per knobs; a batch
// then sums a scenario's changes and counts only the pixels where footprints overlap. No
// image is rendered. It implements the thesis chain on MMW views whose sprites stay at
// their places, with no per-pixel noise (the block-mean model adds its noise after).
#include <algorithm>
#include <memory>

#include "backend/opencl/launch.h"
#include "backend/opencl/paths/paths.h"

namespace portalsim::opencl {

namespace {

class ThesisSparseFeatures final : public FeaturePath {
 public:
  explicit ThesisSparseFeatures(Device& d) : d_(d) {}
  const char* name() const override { return "thesis_sparse_features"; }
  enum Variant { kNoPatterns, kPatterns };
  // Features only, thesis model, sparse pooling, no per-pixel noise, sprites at their places,
  // and the chain the tables implement: thesis_images's, on a view whose kind has the noise
  // patterns; with pattern noise, the tables hold a footprint's change per noise pattern and
  // each scenario's patterns are drawn first.
  // Block sums stay exact in fp32 (255 * 256^2 < 2^24). Not for subjects of their own: a
  // subject's tables take about 19 ms, rendering and pooling a scenario about 0.2 ms.
  Gate gate(const Plan& plan, const Sensor& sensor) const override {
    const bool plan_ok = plan.features && plan.images == 0 && plan.model.model == Model::thesis && !plan.own_subjects &&
                         plan.fidelity.pooling == Pooling::sparse && !plan.pixel_noise_per_pixel() &&
                         plan.model.block <= 256 && !plan.model.moves_sprites();
    if (!plan_ok || !sensor.pattern_noise || sensor.chain_for(plan.model.model) != thesis_images_path().chain() ||
        !FeatureLayout::of(d_.cat, plan.model.block).uniform)
      return {};
    if (plan.model.pattern_noise) return {.runs = true, .variant = kPatterns, .variant_name = "pattern noise"};
    return {.runs = true, .variant = kNoPatterns};
  }
  void features(Kernels& K, const Plan& plan, const Gate& g, const DeviceBatch& b, cl::Buffer& feats) override;

 private:
  // The tables of every pooled view, kept with the first pooled view's derivation.
  struct Tables final : PathTables {
    int patterns = 1;
    bool noise = false;
    cl::Buffer fps, deltas, region_deltas, base_sums, base_means;
  };
  Tables& tables(Kernels& K, const Plan& plan, ViewDerived& derived, bool noise,
                 const std::vector<char>& batch_variants);
  // The tables assume every pooled view has the first one's size (the gate's uniform).
  const Sensor& pooled_view(const FeatureLayout& lay) const { return d_.cat.sensors[lay.pooled.at(0)]; }

  Device& d_;
  Grown patterns_;
};

ThesisSparseFeatures::Tables& ThesisSparseFeatures::tables(Kernels& K, const Plan& plan, ViewDerived& derived,
                                                           bool noise, const std::vector<char>& batch_variants) {
  // The derivation's key holds every knob, so the program variant whose arithmetic made them.
  std::unique_ptr<PathTables>& kept = derived.path_tables;
  auto* old = dynamic_cast<Tables*>(kept.get());
  if (old && old->noise == noise && old->covers(batch_variants)) return *old;
  auto made = std::make_unique<Tables>();  // kept only once whole
  Tables& t = *made;
  t.variants = tabulated_variants(old && old->noise == noise ? old : nullptr, batch_variants);
  const Catalogue& cat = d_.cat;
  const DeviceCatalogue& c = d_.data;
  const ImagesConfig& ic = cat.images;
  const FeatureLayout lay = FeatureLayout::of(cat, plan.model.block);
  const Sensor& view = pooled_view(lay);
  const int block = plan.model.block, W = view.width, H = view.height, N = ic.noise_size;
  const int S = static_cast<int>(cat.subjects.size()), V = static_cast<int>(cat.variant_list.size());
  const int P = noise ? static_cast<int>(cat.noise.size()) : 1;
  // A footprint per (variant, region, subject): the place moves with the subject's height.
  std::vector<cl_int> fps(static_cast<size_t>(V) * lay.regions * S * PS_FP_LEN, 0);
  cl_int offset = 0;
  for (int v = 0; v < V; ++v)
    for (int r = 0; r < lay.regions; ++r)
      for (int s = 0; s < S; ++s) {
        // The region's pooled view: its place and its sprite set's drawing.
        const Sensor& in = cat.sensors[lay.pooled[region_slot(cat, lay, r)]];
        const Image& sp = d_.assets.sprite(in, v);
        const Rect box = sprite_box(in.place(s, r), sp);
        cl_int* f = &fps[((static_cast<size_t>(v) * lay.regions + r) * S + s) * PS_FP_LEN];
        f[PS_FP_SPRITE_X0] = box.x;
        f[PS_FP_SPRITE_Y0] = box.y;
        f[PS_FP_SPRITE_W] = box.w;
        f[PS_FP_SPRITE_H] = box.h;
        f[PS_FP_SPRITE_OFFSET] = c.sprite(in, v).s[0];
        f[PS_FP_SPRITE_PADDED] = c.sprite(in, v).s[3];
        f[PS_FP_TILE_X0] = f[PS_FP_SPRITE_X0] + (sp.width >> 1) - (N >> 1);
        f[PS_FP_TILE_Y0] = f[PS_FP_SPRITE_Y0] + (sp.height >> 1) - (N >> 1);
        int x0 = f[PS_FP_SPRITE_X0], y0 = f[PS_FP_SPRITE_Y0], x1 = f[PS_FP_SPRITE_X0] + f[PS_FP_SPRITE_W],
            y1 = f[PS_FP_SPRITE_Y0] + f[PS_FP_SPRITE_H];
        if (noise) {
          x0 = std::min(x0, f[PS_FP_TILE_X0]);
          y0 = std::min(y0, f[PS_FP_TILE_Y0]);
          x1 = std::max(x1, f[PS_FP_TILE_X0] + N);
          y1 = std::max(y1, f[PS_FP_TILE_Y0] + N);
        }
        x0 = std::max(x0, 0);
        y0 = std::max(y0, 0);
        x1 = std::min(x1, W);
        y1 = std::min(y1, H);
        // Wholly outside, or a drawing no batch carried yet: touches nothing.
        if (x0 >= x1 || y0 >= y1 || !t.variants[v]) x0 = y0 = x1 = y1 = 0;
        f[PS_FP_X0] = x0;
        f[PS_FP_Y0] = y0;
        f[PS_FP_X1] = x1;
        f[PS_FP_Y1] = y1;
        f[PS_FP_BLOCK_X0] = x0 / block;
        f[PS_FP_BLOCK_Y0] = y0 / block;
        f[PS_FP_BLOCKS_W] = x1 > x0 ? (x1 - 1) / block - f[PS_FP_BLOCK_X0] + 1 : 0;
        f[PS_FP_BLOCKS_H] = y1 > y0 ? (y1 - 1) / block - f[PS_FP_BLOCK_Y0] + 1 : 0;
        f[PS_FP_DELTAS] = offset;
        const int64_t next = offset + static_cast<int64_t>(P) * f[PS_FP_BLOCKS_W] * f[PS_FP_BLOCKS_H];
        if (next > INT32_MAX) throw std::runtime_error("sparse feature tables exceed 2^31 entries; use --block larger");
        offset = static_cast<cl_int>(next);
      }
  cl::Context& ctx = d_.ctx();
  cl::CommandQueue& q = d_.queue();
  const int row_len = lay.image_features(), combos = V * lay.regions * S * P;
  t.fps = constant(ctx, fps);
  t.deltas = cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, offset) * sizeof(cl_int));
  t.region_deltas = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(combos) * lay.regions * sizeof(cl_int));
  t.base_sums = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(S) * row_len * sizeof(cl_int));
  t.base_means = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(S) * row_len * sizeof(cl_float));
  const cl_int npooled = static_cast<cl_int>(lay.pooled.size()), views = static_cast<cl_int>(cat.sensors.size());
  enqueue(q, K["base_features"], K.fp64(),
          BaseFeaturesArgs{.atlas = c.atlas,
                           .bases = c.bases,
                           .rects = c.region_rects,
                           .pooled = c.pooled,
                           .npooled = npooled,
                           .views = views,
                           .region_slot = c.region_slot,
                           .subjects = S,
                           .width = W,
                           .height = H,
                           .block = block,
                           .blocks_x = lay.grids[0].blocks_x,
                           .blocks_y = lay.grids[0].blocks_y,
                           .row_len = row_len,
                           .sums = t.base_sums,
                           .means = t.base_means},
          static_cast<size_t>(S) * row_len);
  const FootprintDeltasArgs deltas_args{.atlas = c.atlas,
                                        .bases = c.bases,
                                        .fps = t.fps,
                                        .noise_offsets = c.noise_offsets,
                                        .noise_gains = c.noise_gains,
                                        .rects = c.region_rects,
                                        .pooled = c.pooled,
                                        .views = views,
                                        .region_slot = c.region_slot,
                                        .combos = combos,
                                        .subjects = S,
                                        .patterns = P,
                                        .width = W,
                                        .block = block,
                                        .alpha = {ic.alpha},
                                        .tile = N,
                                        .use_noise = noise ? 1 : 0,
                                        .deltas = t.deltas,
                                        .region_deltas = t.region_deltas};
  // Over the tabulated drawings only, a launch per run of them (combos are variant-major),
  // so that the work is spread over every thread rather than on the first one's range.
  const size_t per_variant = static_cast<size_t>(lay.regions) * S * P;
  for (int v0 = 0; v0 < V;) {
    if (!t.variants[v0]) {
      ++v0;
      continue;
    }
    int v1 = v0;
    while (v1 < V && t.variants[v1]) ++v1;
    enqueue(q, K["footprint_deltas"], K.fp64(), deltas_args, (v1 - v0) * per_variant, v0 * per_variant);
    v0 = v1;
  }
  q.finish();
  t.noise = noise;
  t.patterns = P;
  kept = std::move(made);
  return t;
}

void ThesisSparseFeatures::features(Kernels& K, const Plan& plan, const Gate& g, const DeviceBatch& b,
                                    cl::Buffer& feats) {
  const Catalogue& cat = d_.cat;
  const FeatureLayout lay = FeatureLayout::of(cat, plan.model.block);
  const std::shared_ptr<ViewDerived> derived = d_.derived(plan, lay.pooled.at(0));
  const Tables& t = tables(K, plan, *derived, g.variant == kPatterns, b.variants);
  const DeviceCatalogue& c = d_.data;
  const ImagesConfig& ic = cat.images;
  const Sensor& view = pooled_view(lay);
  cl::CommandQueue& q = d_.queue();
  cl::Buffer& patterns = patterns_.at_least(d_.ctx(), b.n * sizeof(cl_int));
  const cl_uint n = static_cast<cl_uint>(b.n);
  if (t.noise)
    enqueue(
        q, K["sparse_patterns"], K.fp64(),
        SparsePatternsArgs{
            .n = n, .patterns = t.patterns, .seed = b.seed, .first = b.first, .indices = b.indices, .out = patterns},
        b.n);
  enqueue(q, K["features_sparse"], K.fp64(),
          FeaturesSparseArgs{.atlas = c.atlas,
                             .bases = c.bases,
                             .fps = t.fps,
                             .deltas = t.deltas,
                             .region_deltas = t.region_deltas,
                             .base_sums = t.base_sums,
                             .base_means = t.base_means,
                             .noise_offsets = c.noise_offsets,
                             .noise_gains = c.noise_gains,
                             .rects = c.region_rects,
                             .pooled = c.pooled,
                             .npooled = static_cast<cl_int>(lay.pooled.size()),
                             .views = static_cast<cl_int>(cat.sensors.size()),
                             .region_slot = c.region_slot,
                             .subject = b.subject,
                             .objects = b.objects,
                             .patterns = patterns,
                             .n = n,
                             .subjects = static_cast<cl_int>(cat.subjects.size()),
                             .pattern_count = t.patterns,
                             .width = view.width,
                             .height = view.height,
                             .block = lay.block,
                             .blocks_x = lay.grids[0].blocks_x,
                             .blocks_y = lay.grids[0].blocks_y,
                             .alpha = {ic.alpha},
                             .tile = ic.noise_size,
                             .use_noise = t.noise ? 1 : 0,
                             .row_len = lay.image_features(),
                             .features = feats},
          b.n);
}

}  // namespace

std::unique_ptr<FeaturePath> thesis_sparse_features_path(Device& d) {
  return std::make_unique<ThesisSparseFeatures>(d);
}

}  // namespace portalsim::opencl
