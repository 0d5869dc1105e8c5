// The physics model's features-only path (raw_grid_pooling.h, kernels/physics_features.cl):
// per pooled view, the raw grid of the scenarios the tables do not cover (physics_raw,
// noise-free), then physics_features pools it and draws the NETD per feature with the
// covariance per-raw-pixel noise gives. It implements physics_raw's chain, under the
// block-mean noise model (like it, it leaves single pixels' rounding and clipping out).
#include <algorithm>
#include <array>
#include <map>

#include "backend/opencl/display_tables.h"
#include "backend/opencl/launch.h"
#include "backend/opencl/paths/paths.h"
#include "backend/opencl/raw_grid_pooling.h"
#include "base/sizes.h"

namespace portalsim::opencl {

namespace {

// A bound on the pair tables: subjects x (variants x regions)^2, the most (subject, pair)
// entries a run could hold; past it the untabulated kernel runs instead.
constexpr size_t kMaxTabulatedPairs = size_t{1} << 26;
// Global scratch for work spaces too large for private memory, per launch.
constexpr size_t kMaxScratchBytes = 64 * kMiB;

// Whether two boxes, widened by the bilinear fringe, meet (kernels/lib/physics.cl, layers_meet).
bool boxes_meet(const Rect& a, const Rect& b) {
  return a.x - 2 < b.x + b.w + 2 && b.x - 2 < a.x + a.w + 2 && a.y - 2 < b.y + b.h + 2 && b.y - 2 < a.y + a.h + 2;
}

// The pairs (va, ra, vb, rb), ra < rb, of wanted variants in regions the view sees whose
// sprites' boxes meet on any of the S subjects (places move with the height), numbered in
// pair_index by (va R + ra) (V R) + vb R + rb.
std::vector<std::array<int, 4>> meeting_pairs(const AssetSet& assets, const Sensor& sv, int S, int V, int R,
                                              const std::vector<char>& want, std::vector<cl_int>& pair_index) {
  const size_t combos = static_cast<size_t>(V) * R;
  const auto meet = [&](int va, int ra, int vb, int rb) {
    const Image &a = assets.sprite(sv, va), &b = assets.sprite(sv, vb);
    for (int s = 0; s < S; ++s)
      if (boxes_meet(sprite_box(sv.place(s, ra), a), sprite_box(sv.place(s, rb), b))) return true;
    return false;
  };
  std::vector<std::array<int, 4>> pairs;
  for (int ra = 0; ra < R; ++ra)
    for (int rb = ra + 1; rb < R; ++rb)
      if (sv.sees(ra) && sv.sees(rb))
        for (int va = 0; va < V; ++va)
          for (int vb = 0; vb < V; ++vb)
            if (want[va] && want[vb] && meet(va, ra, vb, rb)) {
              pair_index[(static_cast<size_t>(va) * R + ra) * combos + static_cast<size_t>(vb) * R + rb] =
                  static_cast<cl_int>(pairs.size());
              pairs.push_back({va, ra, vb, rb});
            }
  return pairs;
}

class PhysicsRawFeatures final : public FeaturePath {
 public:
  explicit PhysicsRawFeatures(Device& d) : d_(d) {}
  const char* name() const override { return "physics_raw_features"; }
  enum Variant { kUntabulated, kTabulated };
  // Features only, physics model, sparse pooling, the block-mean noise model (the raw grid
  // leaves single pixels' rounding and clipping out), fused, and physics_raw's chain on the
  // view. The tables fold the bilinear interpolation into each feature, in kelvin, and the
  // kernel then applies the window, fixed or the scenario's drawn one; the automatic window
  // (from each raw grid's percentiles), the bicubic filter and smoothing take the dense path.
  Gate gate(const Plan& plan, const Sensor& sensor) const override {
    const ModelSettings& m = plan.model;
    const bool plan_ok = plan.features && plan.images == 0 && m.model == Model::physics &&
                         plan.fidelity.pooling == Pooling::sparse && plan.fidelity.noise == NoiseModel::block_mean &&
                         !m.window_auto && m.display_filter == DisplayFilter::bilinear && m.smooth == 0;
    if (!plan_ok || !physics_raw_path().applies(plan, sensor)) return {};
    // Tables where objects stand at their places and their values are the run's (no drawn
    // illumination, worn time or clothing), and while the pairs' index (subjects x (variants
    // x regions)^2) stays small.
    const size_t combos = d_.cat.variant_list.size() * d_.cat.regions.size();
    const bool scene_drawn = m.drawn[PS_DRAWN_ILLUMINATION].varies() || m.drawn[PS_DRAWN_WORN_MINUTES].varies() ||
                             m.clothing != Clothing::catalogue;
    if (plan.model.jitter <= 0 && !plan.model.transforms() && !scene_drawn &&
        d_.cat.subjects.size() * combos * combos <= kMaxTabulatedPairs)
      return {.runs = true, .variant = kTabulated, .variant_name = "tabulated"};
    return {.runs = true, .variant = kUntabulated, .variant_name = "untabulated"};
  }
  void features(Kernels& K, const Plan& plan, const Gate& g, const DeviceBatch& b, cl::Buffer& feats) override;

 private:
  // A pooled view's tables, kept with its derivation under the noise-free plan.
  struct Tables final : PathTables {
    bool tabulated = false;
    int count = 0;
    cl::Buffer first, cells, weights, columns;
    // blocks_x, blocks_y, band_x, band_y, regions (RawGridNoise), the first block's column, pairs
    cl_int8 dims{};
    cl::Buffer noise, base_features, object_range, pair_index, object_feature, object_value;
  };
  Tables& tables(Kernels& K, const Plan& plan, ViewDerived& derived, const FeatureLayout& lay, int slot, bool tabulated,
                 const std::vector<char>& batch_variants);
  // The raw grid of view `view` for batch b (place_view, then physics_raw) into Device::raw.
  void raw_grid(ViewLaunch& v) {
    v.run("place_view", v.batch.n);
    run_raw_grid(v);
  }

  Device& d_;
  Grown scratch_;
};

void PhysicsRawFeatures::features(Kernels& K, const Plan& plan, const Gate& g, const DeviceBatch& b,
                                  cl::Buffer& feats) {
  const Catalogue& cat = d_.cat;
  const FeatureLayout lay = FeatureLayout::of(cat, plan.model.block);
  const bool tabulated = g.variant == kTabulated;
  cl::Context& ctx = d_.ctx();
  for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
    const int view = lay.pooled[slot];
    // The tables first: making them runs a batch of their own through the same buffers. The
    // raw grid is noise-free: physics_features draws the NETD per feature.
    const std::shared_ptr<ViewDerived> derived = d_.derived(plan, view, true);
    Tables& t = tables(K, plan, *derived, lay, static_cast<int>(slot), tabulated, b.variants);
    ViewLaunch v(d_, K, plan, view, b, d_.pooled_only[view].at_least(ctx, 1), false, tabulated, true);
    raw_grid(v);
    const auto& d = t.dims.s;
    const size_t per = PS_FEATURE_SPACE(size_t(d[0]), size_t(d[1]), size_t(d[2]), size_t(d[3]), size_t(d[4]));
    // Work spaces too large for private memory take global scratch, kMaxScratchBytes at
    // most: a launch per that many scenarios (the kernel indexes it from its launch's offset).
    const size_t rb = K.real_bytes();
    const size_t chunk = per > PS_FEATURE_NOISE_PRIVATE
                             ? std::max<size_t>(kLocalSize, kMaxScratchBytes / (per * rb) / kLocalSize * kLocalSize)
                             : padded(b.n);
    cl::Buffer& scratch =
        scratch_.at_least(ctx, per > PS_FEATURE_NOISE_PRIVATE ? std::min(chunk, padded(b.n)) * per * rb : 1);
    const MmwNoise noise = mmw_noise(plan, plan.model.for_view(cat.sensors[view]));
    const PhysicsFeaturesArgs args{.raw = d_.raw.buf,
                                   .first = t.first,
                                   .cells = t.cells,
                                   .weights = t.weights,
                                   .columns = t.columns,
                                   .count = t.count,
                                   .raw_cells = static_cast<int>(v.derived->raw_values),
                                   .phys = v.args().phys,
                                   .row_len = lay.image_features(),
                                   .features = feats,
                                   .L = v.args().L,
                                   .records = d_.records.buf,
                                   .subject = b.subject,
                                   .objects = b.objects,
                                   .base_features = t.base_features,
                                   .object_range = t.object_range,
                                   .pair_index = t.pair_index,
                                   .object_feature = t.object_feature,
                                   .object_value = t.object_value,
                                   .netd_lo = {noise.netd_lo},
                                   .netd_hi = {noise.netd_hi},
                                   .frames = {{noise.frames_lo, noise.frames_hi}},
                                   .dims = t.dims,
                                   .noise = t.noise,
                                   .scratch = scratch,
                                   .indices = b.indices};
    for (size_t at = 0; at < b.n; at += chunk)
      enqueue(d_.queue(), K["physics_features"], K.fp64(), args, std::min(chunk, padded(b.n) - at), at);
  }
}

// A pooled view's tables for physics_features, made once per (knobs, view, precision):
// the pooling taps, the noise factors and, when `tabulated`, each subject's bare features
// and each (subject, variant, region)'s change to them, made by physics_raw itself on one
// scenario per object (so a tabulated scenario differs from its raw grid only in the order
// of float sums), for the drawings the batches so far carried (PathTables).
PhysicsRawFeatures::Tables& PhysicsRawFeatures::tables(Kernels& K, const Plan& plan, ViewDerived& derived,
                                                       const FeatureLayout& lay, int slot, bool tabulated,
                                                       const std::vector<char>& batch_variants) {
  const Catalogue& cat = d_.cat;
  const int view = lay.pooled[slot];
  const Sensor& sv = cat.sensors[view];
  const ModelSettings& m = derived.model;
  const int RW = m.raw_width, RH = m.raw_height, cells = RW * RH;
  // The derivation's key holds every knob, so the program variant (precision, fast math)
  // whose arithmetic made them too.
  std::unique_ptr<PathTables>& kept = derived.path_tables;
  auto* old = dynamic_cast<Tables*>(kept.get());
  if (old && old->tabulated == tabulated && (!tabulated || old->covers(batch_variants))) return *old;
  auto made = std::make_unique<Tables>();  // kept only once whole
  Tables& t = *made;
  t.tabulated = tabulated;
  t.variants = tabulated_variants(old && old->tabulated == tabulated ? old : nullptr, batch_variants);
  const std::vector<char>& want = t.variants;
  cl::Context& ctx = d_.ctx();
  const bool fp64 = K.fp64();
  const RawGridPooling p = raw_grid_pooling(sv, lay, slot, RW, RH);
  t.count = static_cast<int>(p.columns.size());
  t.cells = constant(ctx, p.cells);
  t.columns = constant(ctx, p.columns);
  t.weights = params(ctx, fp64, p.weights);
  const RawGridNoise z = raw_grid_noise(sv, lay, RW, RH);
  t.dims = {{z.blocks_x, z.blocks_y, z.band_x, z.band_y, z.regions, p.columns.empty() ? 0 : p.columns[0], 0, 0}};
  std::vector<double> noise = z.dx;
  for (const std::vector<double>* v : {&z.dy, &z.region_blocks, &z.region_own})
    noise.insert(noise.end(), v->begin(), v->end());
  t.noise = params(ctx, fp64, noise);
  const int S = static_cast<int>(cat.subjects.size()), V = static_cast<int>(cat.variant_list.size());
  const int R = cat.region_count();
  std::vector<double> bare(static_cast<size_t>(S) * t.count, 0.0), values;
  const size_t combos = static_cast<size_t>(V) * R;
  // [begin, end) per (subject, combo), then per (subject, pair): the pairs are numbered, so
  // that the table grows with the subjects times the pairs, not times combos squared, and an
  // untabulated run makes none (255 drawn bodies' untabulated runs once took 2.6 GB and 15 s
  // for an index they never read).
  std::vector<cl_int2> object_range(S * combos, cl_int2{{0, 0}});
  std::vector<cl_int> pair_index(tabulated ? combos * combos : 1, -1);
  std::vector<cl_int> features;
  if (tabulated) {
    // One scenario per subject bare, per (subject, variant, region seen) alone, and per
    // pair of those whose boxes meet.
    SceneBatch b(R);
    const std::vector<std::array<int, 4>> pairs = meeting_pairs(d_.assets, sv, S, V, R, want, pair_index);
    t.dims.s[6] = static_cast<cl_int>(pairs.size());
    object_range.resize(S * combos + S * pairs.size(), cl_int2{{0, 0}});
    for (int s = 0; s < S; ++s) {
      Scenario sc;
      sc.subject = s;
      b.push(sc);
      for (int v = 0; v < V; ++v)
        for (int r = 0; r < R; ++r)
          if (sv.sees(r) && want[v]) {
            sc.objects.fill(kNoObject);
            sc.objects[r] = static_cast<int16_t>(v);
            b.push(sc);
          }
      for (const auto& [va, ra, vb, rb] : pairs) {
        sc.objects.fill(kNoObject);
        sc.objects[ra] = static_cast<int16_t>(va);
        sc.objects[rb] = static_cast<int16_t>(vb);
        b.push(sc);
      }
    }
    const size_t N = b.size();
    const DeviceBatch table_batch{.n = N,
                                  .subject = constant(ctx, b.subject),
                                  .objects = constant(ctx, b.objects),
                                  .seed = {{0, 0}},
                                  .first = {{0, 0}},
                                  .indices = {},
                                  .variants = {}};
    ViewLaunch v(d_, K, plan, view, table_batch, d_.pooled_only[view].at_least(ctx, 1), false, false, true);
    raw_grid(v);
    std::vector<double> raw(N * cells);
    if (fp64) {
      d_.queue().enqueueReadBuffer(d_.raw.buf, CL_TRUE, 0, N * cells * sizeof(cl_double), raw.data());
    } else {
      std::vector<cl_float> f(N * cells);
      d_.queue().enqueueReadBuffer(d_.raw.buf, CL_TRUE, 0, N * cells * sizeof(cl_float), f.data());
      raw.assign(f.begin(), f.end());
    }
    // Feature f of a raw grid: its taps' weighted sum.
    const auto pooled = [&](const double* g, int f) {
      double d = 0;
      for (int k = p.first[f]; k < p.first[f + 1]; ++k) d += p.weights[k] * g[p.cells[k]];
      return d;
    };
    // The features of sum_k sign_k raw[scenario_k], kept where not zero.
    std::vector<double> grid(cells);
    const auto entries = [&](size_t u, std::initializer_list<std::pair<size_t, double>> terms) {
      std::fill(grid.begin(), grid.end(), 0.0);
      for (const auto& [scenario, sign] : terms)
        for (int c = 0; c < cells; ++c) grid[c] += sign * raw[scenario * cells + c];
      object_range[u].s[0] = static_cast<cl_int>(features.size());
      for (int f = 0; f < t.count; ++f) {
        const double d = pooled(grid.data(), f);
        if (d == 0) continue;
        features.push_back(f);
        values.push_back(d);
      }
      object_range[u].s[1] = static_cast<cl_int>(features.size());
      if (features.size() > INT32_MAX) throw std::runtime_error("physics feature tables exceed 2^31 entries");
    };
    size_t at = 0;
    std::vector<size_t> alone(combos);
    for (int s = 0; s < S; ++s) {
      const size_t bare_at = at++;
      for (int f = 0; f < t.count; ++f) bare[static_cast<size_t>(s) * t.count + f] = pooled(&raw[bare_at * cells], f);
      for (int v = 0; v < V; ++v)
        for (int r = 0; r < R; ++r) {
          const size_t c = static_cast<size_t>(v) * R + r;
          if (sv.sees(r) && want[v]) {
            alone[c] = at++;
            entries(s * combos + c, {{alone[c], 1.0}, {bare_at, -1.0}});
          }
        }
      // Pairs: both together less each alone, plus the bare grid counted twice over.
      for (size_t q = 0; q < pairs.size(); ++q) {
        const auto& [va, ra, vb, rb] = pairs[q];
        const size_t a = static_cast<size_t>(va) * R + ra, c = static_cast<size_t>(vb) * R + rb;
        entries(S * combos + s * pairs.size() + q, {{at++, 1.0}, {alone[a], -1.0}, {alone[c], -1.0}, {bare_at, 1.0}});
      }
    }
  }
  t.base_features = params(ctx, fp64, bare);
  t.object_range = constant(ctx, object_range);
  t.pair_index = constant(ctx, pair_index);
  t.object_feature = constant(ctx, features);
  t.object_value = params(ctx, fp64, values);
  t.first = constant(ctx, p.first);
  kept = std::move(made);
  return t;
}

}  // namespace

std::unique_ptr<FeaturePath> physics_raw_features_path(Device& d) { return std::make_unique<PhysicsRawFeatures>(d); }

}  // namespace portalsim::opencl
