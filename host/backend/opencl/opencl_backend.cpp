#include "backend/opencl/opencl_backend.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "backend/opencl/display_tables.h"
#include "backend/opencl/gauss_table.h"
#include "backend/opencl/raw_grid_pooling.h"
#include "backend/stages.h"
#include "base/error.h"

namespace portalsim {

namespace {

cl_uint2 split(uint64_t v) {
  cl_uint2 r;
  r.s[0] = static_cast<cl_uint>(v);
  r.s[1] = static_cast<cl_uint>(v >> 32);
  return r;
}

// A device buffer that grows to the largest batch seen and is then reused.
struct Grown {
  cl::Buffer buf;
  size_t bytes = 0;
  cl::Buffer& at_least(cl::Context& ctx, size_t want) {
    if (want > bytes || bytes == 0) {
      bytes = std::max<size_t>(want, 1);
      buf = cl::Buffer(ctx, CL_MEM_READ_WRITE, bytes);
    }
    return buf;
  }
};

template <class T>
cl::Buffer constant(cl::Context& ctx, const std::vector<T>& v) {
  std::vector<T> copy = v;
  if (copy.empty()) copy.resize(1);
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, copy.size() * sizeof(T), copy.data());
}

cl_int4 rect4(const Rect& r) { return {{r.x, r.y, r.w, r.h}}; }

// A sprite centred in a region's rectangle (>> 1 floors negative differences too): where
// place_view lays it without jitter, given the region's place on the subject.
Rect sprite_box(const Rect& rc, const Image& sprite) {
  return {rc.x + ((rc.w - sprite.width) >> 1), rc.y + ((rc.h - sprite.height) >> 1), sprite.width, sprite.height};
}

// Whether two boxes, widened by the bilinear fringe, meet (kernels/physics_raw.cl, layers_meet).
bool boxes_meet(const Rect& a, const Rect& b) {
  return a.x - 2 < b.x + b.w + 2 && b.x - 2 < a.x + a.w + 2 && a.y - 2 < b.y + b.h + 2 && b.y - 2 < a.y + a.h + 2;
}

class OpenCLBackend final : public Backend {
 public:
  OpenCLBackend(const Catalogue& cat, const AssetSet& assets, std::shared_ptr<OpenCLRuntime> rt)
      : cat_(cat), assets_(assets), rt_(std::move(rt)) {
    for (const Sensor& s : cat.sensors) check_chain(s);
    std::vector<uint8_t> atlas;
    auto add = [&](const Image& img) {
      const int off = static_cast<int>(atlas.size());
      atlas.insert(atlas.end(), img.pixels.begin(), img.pixels.end());
      return off;
    };
    const size_t V = cat.variant_list.size(), views = cat.sensors.size();
    std::vector<cl_int> bases;
    for (const auto& subject_views : assets.bases)
      for (const Image& img : subject_views) bases.push_back(add(img));
    // The vector render path's copies (kernels/shared.h, PS_PAD): each sprite row as a
    // value row and a coverage row, each tile row, with neutral pixels on both sides.
    auto add_padded_sprite = [&](const Image& img) {
      const int off = static_cast<int>(atlas.size());
      for (int y = 0; y < img.height; ++y)
        for (int c = 0; c < 2; ++c) {
          atlas.insert(atlas.end(), PS_PAD, 0);
          for (int x = 0; x < img.width; ++x) atlas.push_back(img.at(x, y, c));
          atlas.insert(atlas.end(), PS_PAD, 0);
        }
      return off;
    };
    auto add_padded_tile = [&](const Image& img) {
      const int off = static_cast<int>(atlas.size());
      for (int y = 0; y < img.height; ++y) {
        atlas.insert(atlas.end(), PS_PAD, 128);
        for (int x = 0; x < img.width; ++x) atlas.push_back(img.at(x, y));
        atlas.insert(atlas.end(), PS_PAD, 128);
      }
      return off;
    };
    std::vector<cl_int4> sprites(kCameras * V);
    for (int c = 0; c < kCameras; ++c)
      for (size_t v = 0; v < V; ++v) {
        const Image& sp = assets.sprites[c][v];
        const int plain = add(sp);
        sprites[c * V + v] = {{plain, sp.width, sp.height, add_padded_sprite(sp)}};
      }
    // Each sprite centred in its region's rectangle of each view; then, per subject and
    // view, how far each region's place moves with the subject's height (Sensor::place),
    // which place_view adds.
    const size_t S = cat.subjects.size();
    std::vector<cl_int2> places((views * V + S * views) * kRegions);
    for (size_t k = 0; k < views; ++k) {
      const Sensor& s = cat.sensors[k];
      for (size_t v = 0; v < V; ++v) {
        const Image& sp = assets.sprite(s.camera, static_cast<int>(v));
        for (int r = 0; r < kRegions; ++r) {
          const Rect box = sprite_box(s.rects[r], sp);
          places[(k * V + v) * kRegions + r] = {{box.x, box.y}};
        }
      }
      for (size_t j = 0; j < S; ++j)
        for (int r = 0; r < kRegions; ++r)
          places[(views * V + j * views + k) * kRegions + r] = {{0, s.subject_dy[j][r]}};
    }
    std::vector<cl_int> noise_offsets;
    std::vector<cl_float> noise_gains;
    for (size_t k = 0; k < assets.noise.size(); ++k) {
      noise_offsets.push_back(add(assets.noise[k]));
      noise_gains.push_back(static_cast<float>(cat.noise[k].gain));
    }
    for (const Image& tile : assets.noise) noise_offsets.push_back(add_padded_tile(tile));
    if (atlas.size() > 0x7fffffffu) throw std::runtime_error("catalogue images exceed 2 GiB");
    mmw_sprites_.assign(sprites.begin() + static_cast<int>(Camera::mmw) * V,
                        sprites.begin() + (static_cast<int>(Camera::mmw) + 1) * V);

    // Pooled views: each region's rectangle in the pooled view that sees it.
    const FeatureLayout lay = FeatureLayout::of(cat, 1);
    std::vector<cl_int> pooled(lay.pooled.begin(), lay.pooled.end()), region_slot(kRegions, 0);
    std::vector<cl_int4> region_rects(kRegions);
    for (int r = 0; r < kRegions; ++r)
      for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
        const Sensor& s = cat.sensors[lay.pooled[slot]];
        if (!s.sees(r)) continue;
        region_slot[r] = static_cast<cl_int>(slot);
        region_rects[r] = rect4(s.rects[r]);
        break;
      }
    std::vector<cl_int4> view_rects;
    for (const Sensor& s : cat.sensors)
      for (const Rect& rc : s.rects) view_rects.push_back(rect4(rc));

    std::vector<uint8_t> influence, categories, base_zones;
    for (const auto& table : cat.influence)
      for (const auto& row : table)
        for (int z : row) influence.push_back(static_cast<uint8_t>(z));
    for (size_t v = 0; v < V; ++v) categories.push_back(static_cast<uint8_t>(cat.object_of(static_cast<int>(v)).metal));
    for (const Subject& s : cat.subjects)
      for (int z : s.base_zones) base_zones.push_back(static_cast<uint8_t>(z));

    cl::Context& ctx = rt_->context();
    atlas_ = constant(ctx, atlas);
    bases_ = constant(ctx, bases);
    sprites_ = constant(ctx, sprites);
    places_ = constant(ctx, places);
    noise_offsets_ = constant(ctx, noise_offsets);
    noise_gains_ = constant(ctx, noise_gains);
    pooled_ = constant(ctx, pooled);
    region_slot_ = constant(ctx, region_slot);
    region_rects_ = constant(ctx, region_rects);
    for (size_t k = 0; k < views; ++k)
      view_rects_.push_back(constant(
          ctx, std::vector<cl_int4>(view_rects.begin() + k * kRegions, view_rects.begin() + (k + 1) * kRegions)));
    if (cat.metal_physics.present) metal_physics_tables(ctx);
    influence_ = constant(ctx, influence);
    categories_ = constant(ctx, categories);
    base_zones_ = constant(ctx, base_zones);
    scratch_.resize(views);
  }

  std::string name() const override { return "opencl"; }

  void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) override {
    const size_t n = batch.size();
    prepare_output(out, cat_, plan, n);
    if (n == 0) {
      annotations(cat_, assets_, batch, plan, out);
      return;
    }
    const FeatureLayout& lay = out.layout;

    cl::Context& ctx = rt_->context();
    cl::CommandQueue& q = rt_->queue();
    Kernels& K = kernels_for(plan.fidelity);
    cl::Buffer& subject = subject_.at_least(ctx, n);
    cl::Buffer& objects = objects_.at_least(ctx, n * kRegions * sizeof(int16_t));
    q.enqueueWriteBuffer(subject, CL_FALSE, 0, n, batch.subject.data());
    q.enqueueWriteBuffer(objects, CL_FALSE, 0, n * kRegions * sizeof(int16_t), batch.objects.data());
    const cl_uint2 seed = split(plan.model.seed), first = split(batch.first_index);

    const bool sparse = plan.sparse_features(), raw_grid = plan.physics_sparse_features();
    // Features are written straight into the caller's rows, as kept images are.
    cl::Buffer feats;
    if (plan.features) feats = wrap(out.features);
    if (plan.features && sparse) sparse_features(K, plan, n, subject, objects, seed, first, feats);
    if (plan.features && raw_grid) raw_grid_features(K, plan, n, subject, objects, seed, first, feats);

    // Each camera view the plan needs: rendered into the caller's buffer when its images
    // are kept (PoCL on the CPU writes there directly), else into a device buffer that
    // only pooling reads.
    std::vector<cl::Buffer> rendered(cat_.sensors.size());
    for (size_t k = 0; k < cat_.sensors.size(); ++k) {
      const Sensor& s = cat_.sensors[k];
      const int view = static_cast<int>(k);
      const bool keep = plan.image(view);
      if (!keep && !(plan.features && s.pooled && !sparse && !raw_grid)) continue;
      rendered[k] = keep ? wrap(out.views[k].pixels) : scratch_[k].at_least(ctx, n * s.pixels());
      render(K, plan, view, n, subject, objects, seed, first, rendered[k]);
    }
    if (plan.features && !sparse && !raw_grid) {
      for (size_t slot = 0; slot < lay.pooled.size(); ++slot)
        pool(K, lay, n, static_cast<int>(slot), rendered[lay.pooled[slot]], feats);
    }
    if (plan.features && plan.model.pixel_sigma > 0 && !plan.pixel_noise_per_pixel())
      analytic_noise(K, plan, n, seed, first, feats);
    // The host's boxes and masks while PoCL's threads run what is queued (their outputs
    // are apart); the maps below wait for the kernels.
    q.flush();
    annotations(cat_, assets_, batch, plan, out);
    if (plan.features) sync(feats, out.features);
    for (size_t k = 0; k < cat_.sensors.size(); ++k)
      if (plan.image(static_cast<int>(k))) sync(rendered[k], out.views[k].pixels);
    if (plan.metal && plan.model.model == Model::physics) {
      metal_physics(K, plan, n, subject, objects, seed, first, out);
    } else if (plan.metal) {
      cl::Buffer& metal = metal_out_.at_least(ctx, n * kZones);
      int a = 0;
      K.metal.setArg(a++, influence_);
      K.metal.setArg(a++, categories_);
      K.metal.setArg(a++, base_zones_);
      K.metal.setArg(a++, subject);
      K.metal.setArg(a++, objects);
      K.metal.setArg(a++, static_cast<cl_uint>(n));
      K.metal.setArg(a++, seed);
      K.metal.setArg(a++, first);
      K.metal.setArg(a++, static_cast<cl_int>(plan.model.metal_noise));
      K.metal.setArg(a++, metal);
      q.enqueueNDRangeKernel(K.metal, cl::NullRange, cl::NDRange(padded(n)), cl::NDRange(kLocalSize));
      q.enqueueReadBuffer(metal, CL_FALSE, 0, n * kZones, out.metal.data());
    }
    q.finish();
  }

 private:
  // The kernels of one program variant (precision, fast math).
  struct SparseTables {
    int block = -1;
    bool noise = false;
    int patterns = 1;
    cl::Buffer fps, deltas, region_deltas, base_sums, base_means;
  };
  struct Kernels {
    cl::Program program;
    cl::Kernel place, render, pool_blocks, pool_regions, metal, base_features, footprint_deltas, sparse_patterns,
        features_sparse, analytic_noise;
    cl::Kernel metal_physics;                  // made on first use: needs cl_khr_fp64
    std::map<std::string, cl::Kernel> stages;  // stage kernels and fast paths, made on first use
    SparseTables tables;
    bool fp64 = false;  // alpha and sigma are passed as double
    size_t real_bytes = sizeof(cl_float);
  };

  // The coil model's tables (kernels/shared.h, PS_MZ_* and PS_MR_*) and each variant's
  // polarizability tensor, as the reference computes them.
  void metal_physics_tables(cl::Context& ctx) {
    const MetalPhysics& mp = cat_.metal_physics;
    const size_t S = cat_.subjects.size();
    std::vector<cl_double> zones(kZones * PS_MZ_LEN, 0.0), regions(S * kRegions * PS_MR_LEN, 0.0), tensors;
    for (int z = 0; z < kZones; ++z) {
      const double side = z < PS_METAL_PANEL_A_ZONES ? -1.0 : 1.0;
      cl_double* rec = &zones[z * PS_MZ_LEN];
      rec[PS_MZ_TX_X] = side * mp.panel_separation / 2.0;
      rec[PS_MZ_TX_Z] = mp.tx_height[z];
      rec[PS_MZ_TX_M] = -side * mp.tx_moment;
      rec[PS_MZ_RX_X] = -side * mp.panel_separation / 2.0;
      rec[PS_MZ_RX_Z] = mp.rx_height[z];
      rec[PS_MZ_RX_M] = side * mp.rx_moment;
      rec[PS_MZ_GAIN] = mp.gain[z < PS_METAL_PANEL_A_ZONES ? 0 : 1];
    }
    double row_offset = 0;  // the MMW views stacked, the first on top
    for (const Sensor& s : cat_.sensors) {
      if (s.camera != Camera::mmw) continue;
      if (!metal_view_) metal_view_ = &s;
      // Each subject's region centres: the places, moved with its height.
      for (size_t j = 0; j < S; ++j)
        for (int r = 0; r < kRegions; ++r)
          if (s.sees(r)) {
            const Rect rc = s.place(static_cast<int>(j), r);
            cl_double* rec = &regions[(j * kRegions + r) * PS_MR_LEN];
            rec[PS_MR_COL] = rc.x + rc.w / 2.0;
            rec[PS_MR_ROW] = row_offset + rc.y + rc.h / 2.0;
          }
      row_offset += s.height;
    }
    for (size_t v = 0; v < cat_.variant_list.size(); ++v)
      for (double e : cat_.polarizability(static_cast<int>(v))) tensors.push_back(e);
    metal_zone_rec_ = constant(ctx, zones);
    metal_region_rec_ = constant(ctx, regions);
    metal_tensors_ = constant(ctx, tensors);
  }

  void metal_physics(Kernels& K, const Plan& plan, size_t n, cl::Buffer& subject, cl::Buffer& objects, cl_uint2 seed,
                     cl_uint2 first, BatchOutput& out) {
    if (!rt_->has_fp64())
      throw EnvironmentError("--model physics computes metal zones in fp64, and " + rt_->device_name() +
                             " has no cl_khr_fp64; --backend reference works without it");
    if (!cat_.metal_physics.present || !metal_view_)
      throw InputError("--model physics: the catalogue has no [metal.physics] section");
    if (!K.metal_physics()) K.metal_physics = cl::Kernel(K.program, "metal_physics");
    cl::Kernel& k = K.metal_physics;
    const MetalPhysics& mp = cat_.metal_physics;
    cl::Buffer& metal = metal_out_.at_least(rt_->context(), n * kZones);
    int a = 0;
    k.setArg(a++, metal_zone_rec_);
    k.setArg(a++, metal_region_rec_);
    k.setArg(a++, metal_tensors_);
    k.setArg(a++, base_zones_);
    k.setArg(a++, subject);
    k.setArg(a++, objects);
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, seed);
    k.setArg(a++, first);
    k.setArg(a++, static_cast<cl_int>(plan.model.metal_noise));
    // The reference's jitter, (jitter * scale) * (2u - 1), in the MMW views' pixels.
    k.setArg(a++, static_cast<cl_double>(plan.model.jitter * metal_view_->jitter_scale_x));
    k.setArg(a++, static_cast<cl_double>(plan.model.jitter * metal_view_->jitter_scale_y));
    k.setArg(a++, static_cast<cl_double>(metal_view_->width / 2.0));
    k.setArg(a++, static_cast<cl_double>(mp.body_height / (2.0 * cat_.images.mmw_height)));
    k.setArg(a++, static_cast<cl_double>(mp.body_height));
    k.setArg(a++, metal);
    cl::CommandQueue& q = rt_->queue();
    q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(padded(n)), cl::NDRange(kLocalSize));
    q.enqueueReadBuffer(metal, CL_FALSE, 0, n * kZones, out.metal.data());
  }

  // A model parameter at the kernels' parameter precision (see kernels/precision.cl).
  static void set_param(const Kernels& K, cl::Kernel& k, int index, double v) {
    if (K.fp64)
      k.setArg(index, static_cast<cl_double>(v));
    else
      k.setArg(index, static_cast<cl_float>(v));
  }

  // One camera view for the batch: the fused kernel, or the chain of stage kernels over a
  // field buffer. Both take VIEW_STAGE_ARGS (kernels/composite.cl).
  // raw_only: the physics MMW fast path's raw grid alone (into raw_), for raw_grid_features;
  // tabulated: it skips the scenarios whose features come from tables (PS_FLAG_TABULATED).
  // *launched: the launch's settings, for kernels that follow.
  void render(Kernels& K, const Plan& plan, int view, size_t n, cl::Buffer& subject, cl::Buffer& objects, cl_uint2 seed,
              cl_uint2 first, cl::Buffer& dst, bool raw_only = false, bool tabulated = false,
              PsViewLaunch* launched = nullptr) {
    const Sensor& s = cat_.sensors[view];
    PsViewLaunch L{};
    L.n = static_cast<uint32_t>(n);
    L.view = view;
    L.views = static_cast<int32_t>(cat_.sensors.size());
    L.sprite_set = static_cast<int32_t>(s.camera);
    L.variants = static_cast<int32_t>(cat_.variant_list.size());
    L.region_mask = s.region_mask;
    L.width = s.width;
    L.height = s.height;
    L.seed_lo = seed.s[0];
    L.seed_hi = seed.s[1];
    L.first_lo = first.s[0];
    L.first_hi = first.s[1];
    L.patterns = static_cast<int32_t>(cat_.noise.size());
    L.tile_size = cat_.images.noise_size;
    L.flags = (s.pattern_noise && plan.model.pattern_noise ? PS_FLAG_PATTERN_NOISE : 0) |
              (plan.pixel_noise_per_pixel() ? PS_FLAG_PIXEL_NOISE : 0) | (plan.model.bilinear ? PS_FLAG_BILINEAR : 0) |
              (plan.model.transforms() ? PS_FLAG_AFFINE : 0) | (plan.model.flip ? PS_FLAG_FLIP : 0) |
              (tabulated ? PS_FLAG_TABULATED : 0);
    L.jitter_x = static_cast<float>(plan.model.jitter * s.jitter_scale_x);
    L.jitter_y = static_cast<float>(plan.model.jitter * s.jitter_scale_y);
    L.rotate_lo = static_cast<float>(plan.model.rotate_lo);
    L.rotate_hi = static_cast<float>(plan.model.rotate_hi);
    L.scale_lo = static_cast<float>(plan.model.scale_lo);
    L.scale_hi = static_cast<float>(plan.model.scale_hi);
    const double ranges[4] = {plan.model.rotate_lo, plan.model.rotate_hi, plan.model.scale_lo, plan.model.scale_hi};
    std::memcpy(L.ranges_fp64, ranges, sizeof ranges);  // little-endian host and device: low word first
    L.raw_width = plan.model.raw_width;
    L.raw_height = plan.model.raw_height;
    L.frames = kernel_frames(plan);
    L.window_auto = plan.model.window_auto;
    L.subjects = static_cast<int32_t>(cat_.subjects.size());
    const std::vector<std::string>& chain = s.chain_for(plan.model.model);
    const bool fused = plan.fidelity.fused && chain == fused_chain();
    const bool physics_fast = plan.fidelity.fused && chain == physics_fused_chain();
    const std::vector<std::string>& ir_prefix = ir_fused_chain();
    const bool ir_fast = plan.fidelity.fused && chain.size() > ir_prefix.size() &&
                         std::equal(ir_prefix.begin(), ir_prefix.end(), chain.begin());
    cl::Context& ctx = rt_->context();
    cl::Buffer field = fused || physics_fast ? dst : field_.at_least(ctx, n * s.pixels() * K.real_bytes);
    cl::Buffer& records = records_.at_least(ctx, n * PS_REC_LEN * sizeof(cl_int));
    cl::Buffer phys = physics_params(K, plan, view, L);
    if (launched) *launched = L;
    const bool physics = plan.model.model == Model::physics;
    cl::Buffer& raw = raw_.at_least(ctx, physics ? n * plan.model.raw_width * plan.model.raw_height * K.real_bytes : 1);
    // Physics, per scenario: a second field for the stage chain; physics_raw's row sums;
    // stage_mmw_display's interpolated rows; ir_surface_fused's row blur and row spans.
    const size_t scratch_values = std::max({s.pixels(), size_t(s.width) + plan.model.raw_width,
                                            mmw_display_scratch(s, plan.model.raw_width, plan.model.raw_height),
                                            s.pixels() + 2 * size_t(s.height)});
    cl::Buffer& scratch = view_scratch_.at_least(ctx, physics ? n * scratch_values * K.real_bytes : 1);
    const auto launch = [&](cl::Kernel& k, size_t items) {
      int a = 0;
      k.setArg(a++, atlas_);
      k.setArg(a++, bases_);
      k.setArg(a++, sprites_);
      k.setArg(a++, places_);
      k.setArg(a++, noise_offsets_);
      k.setArg(a++, noise_gains_);
      k.setArg(a++, subject);
      k.setArg(a++, objects);
      k.setArg(a++, sizeof(L), &L);
      set_param(K, k, a++, cat_.images.alpha);
      set_param(K, k, a++, plan.model.pixel_sigma);
      k.setArg(a++, records);
      k.setArg(a++, field);
      k.setArg(a++, dst);
      k.setArg(a++, phys);
      k.setArg(a++, raw);
      k.setArg(a++, scratch);
      rt_->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(padded(items)), cl::NDRange(kLocalSize));
    };
    launch(K.place, n);  // one placement record per scenario, read by every row below
    if (fused) {
      launch(K.render, n);  // one work-item per scenario, the whole view
      return;
    }
    if (raw_only && !physics_fast) throw std::logic_error("the raw grid alone needs the physics fast path");
    if (physics_fast) {
      launch(stage_kernel(K, "physics_raw"), n);
      if (raw_only) return;
      if (plan.model.window_auto) launch(stage_kernel(K, "stage_window"), n);
      launch(stage_kernel(K, "stage_mmw_display"), n);
      return;
    }
    const auto per_scenario = [&](StageItems items) -> size_t {
      switch (items) {
        case StageItems::view_rows:
          return static_cast<size_t>(s.height);
        case StageItems::raw_rows:
          return static_cast<size_t>(plan.model.raw_height);
        case StageItems::scenarios:
          return 1;
      }
      throw std::logic_error("unknown stage items");
    };
    size_t from = 0;
    if (ir_fast) {
      // Where the chain leaves only ir_display (ir_netd at 0 K draws nothing), the fast
      // path shows the surface itself; where it leaves ir_netd then ir_display, it draws
      // the noise and shows it in one pass too.
      std::vector<std::string> rest(chain.begin() + static_cast<std::ptrdiff_t>(ir_prefix.size()), chain.end());
      if (plan.model.ir_netd == 0) std::erase(rest, "ir_netd");
      if (rest == std::vector<std::string>{"ir_display"}) {
        launch(stage_kernel(K, "ir_surface_display_fused"), n);
        return;
      }
      if (rest == std::vector<std::string>{"ir_netd", "ir_display"}) {
        launch(stage_kernel(K, "ir_surface_noise_display_fused"), n);
        return;
      }
      launch(stage_kernel(K, "ir_surface_fused"), n);
      from = ir_prefix.size();
    }
    for (size_t k = from; k < chain.size(); ++k)
      for (const StageKernel& sk : view_stage(chain[k]).kernels)
        launch(stage_kernel(K, sk.kernel), n * per_scenario(sk.items));
  }

  // stage_mmw_display's scratch values per scenario: each view row's vertically
  // interpolated raw row, then 16 values per raw row for the pixels after the last run of 16.
  static size_t mmw_display_scratch(const Sensor& s, int raw_width, int raw_height) {
    return size_t(s.height) * raw_width + 16 * size_t(raw_height);
  }

  static cl::Kernel& stage_kernel(Kernels& K, std::string_view name) {
    const std::string kernel(name);
    auto it = K.stages.find(kernel);
    if (it == K.stages.end()) it = K.stages.emplace(kernel, cl::Kernel(K.program, kernel.c_str())).first;
    return it->second;
  }

  // The physics model's parameters for a view's launch (kernels/shared.h, PS_PHYS_*), at the
  // kernels' parameter precision, with the MMW fast path's tables; fills L's offsets into
  // them. The same formulas as the reference's, written again here: the two never share
  // code. Kept per (view, knobs, precision): the bare raw grids cost a few milliseconds.
  cl::Buffer physics_params(const Kernels& K, const Plan& plan, int view, PsViewLaunch& L) {
    L.psf_radius = L.phys_wx = L.phys_wy = L.phys_cband = L.phys_rband = L.phys_base = L.phys_gauss = 0;
    if (plan.model.model != Model::physics) return physics_none_.at_least(rt_->context(), 16);
    const ModelSettings& m = plan.model;
    char key[300];
    std::snprintf(key, sizeof key, "%d %d %a %a %a %a %d %d %a %a %a %d %a", view, int(K.fp64), m.illumination,
                  kernel_netd(plan), m.ir_netd, m.worn_minutes, m.raw_width, m.raw_height, m.window_lo, m.window_hi,
                  m.smooth, int(m.display_filter), double(m.frames));
    PhysicsTables& t = physics_tables_[key];
    if (t.values.empty()) t = physics_tables(plan, cat_.sensors[view], view);
    L.psf_radius = t.radius;
    L.phys_wx = t.wx;
    L.phys_wy = t.wy;
    L.phys_cband = t.cband;
    L.phys_rband = t.rband;
    L.phys_base = t.base;
    L.phys_gauss = t.gauss;
    L.display_stride = t.display.stride;
    L.phys_dx = t.display.dx;
    L.phys_dxband = t.display.dxband;
    L.phys_dy = t.display.dy;
    L.phys_dyband = t.display.dyband;
    if (!t.buffer()) {
      t.buffer = K.fp64 ? constant(rt_->context(), t.values)
                        : constant(rt_->context(), std::vector<cl_float>(t.values.begin(), t.values.end()));
    }
    return t.buffer;
  }

  struct PhysicsTables {
    std::vector<double> values;
    int32_t radius = 0, wx = 0, wy = 0, cband = 0, rband = 0, base = 0, gauss = 0;
    DisplayTables display;
    cl::Buffer buffer;
  };

  // An object's physical temperature after `worn` minutes on the body: from the room towards
  // the skin with its material's time constant.
  static double worn_temperature(const PhysicsConfig& pc, const Material& mat, double worn) {
    return pc.skin_temperature - (pc.skin_temperature - pc.room_temperature) * std::exp(-worn / mat.warm_minutes);
  }

  // A Gaussian of `sigma` taps over +-4 sigma, normalised; sigma 0 is the single tap 1.
  static void append_gaussian_taps(std::vector<double>& p, double sigma, int32_t& radius) {
    radius = sigma > 0 ? static_cast<int32_t>(std::ceil(4.0 * sigma)) : 0;
    double total = 0;
    const size_t first = p.size();
    for (int d = -radius; d <= radius; ++d) {
      p.push_back(sigma > 0 ? std::exp(-0.5 * d * d / (sigma * sigma)) : 1.0);
      total += p.back();
    }
    for (size_t k = first; k < p.size(); ++k) p[k] /= total;
  }

  // The raw grid's weight of each view pixel along one axis (size pixels, raw cells): the
  // PSF's taps (edges held) folded into each cell's box over size / raw pixels; then the
  // first and last cell each pixel reaches.
  static void axis_weights(int size, int raw, const double* taps, int radius, std::vector<double>& w,
                           std::vector<double>& band) {
    w.assign(static_cast<size_t>(raw) * size, 0.0);
    const double step = double(size) / raw;
    for (int c = 0; c < raw; ++c)
      for (int x = static_cast<int>(std::floor(c * step)); x < std::min(size, int(std::ceil((c + 1) * step))); ++x) {
        const double share = (std::min(x + 1.0, (c + 1) * step) - std::max(double(x), c * step)) / step;
        for (int d = -radius; d <= radius; ++d)
          w[size_t(c) * size + std::clamp(x + d, 0, size - 1)] += share * taps[d + radius];
      }
    band.assign(2 * static_cast<size_t>(size), 0.0);
    for (int x = 0; x < size; ++x) {
      int lo = raw, hi = -1;
      for (int c = 0; c < raw; ++c)
        if (w[size_t(c) * size + x] != 0) lo = std::min(lo, c), hi = std::max(hi, c);
      band[2 * x] = lo;
      band[2 * x + 1] = hi;
    }
  }

  PhysicsTables physics_tables(const Plan& plan, const Sensor& s, int view) const {
    const PhysicsConfig& pc = cat_.physics;
    const ModelSettings& m = plan.model;
    const bool ir = s.camera == Camera::ir;
    const auto seen = [&](double e, double t) {
      return pc.clothing_transmission * (e * t + (1 - e) * m.illumination) +
             (1 - pc.clothing_transmission) * pc.clothing_temperature;
    };
    PhysicsTables t;
    std::vector<double>& p = t.values;
    p.assign(PS_PHYS_SUBJECTS, 0.0);
    p[PS_PHYS_BACKGROUND] = pc.background_temperature;
    p[PS_PHYS_WINDOW_MIN] = ir ? pc.ir_display_min : m.window_lo;
    p[PS_PHYS_WINDOW_MAX] = ir ? pc.ir_display_max : m.window_hi;
    p[PS_PHYS_NETD] = ir ? m.ir_netd : kernel_netd(plan);
    // Per subject, its base image's value to kelvin: the IR index map, or the MMW's gray
    // between the room behind and the bare body.
    const double body = seen(pc.skin_emissivity, pc.skin_temperature);
    for (const Subject& subj : cat_.subjects) {
      const double gain = ir ? (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0
                             : (body - pc.background_temperature) / (subj.mmw_level - pc.base_background_gray);
      p.push_back(gain);
      p.push_back(ir ? pc.ir_index_min_k : pc.background_temperature - gain * pc.base_background_gray);
    }
    // Per variant: the IR surface's contact shadow, or the MMW apparent temperature.
    for (size_t v = 0; v < cat_.variant_list.size(); ++v) {
      const Material& mat = cat_.materials.at(cat_.object_of(static_cast<int>(v)).material_id);
      const double worn = worn_temperature(pc, mat, m.worn_minutes);
      p.push_back(ir ? -pc.ir_coupling * (pc.skin_temperature - worn) : seen(mat.emissivity, worn));
    }
    // MMW: the Airy core's FWHM, 1.02 lambda / D at the range, in this view's pixels, as a
    // Gaussian of that FWHM. IR: ir_spread_mm over the view's pixel (as wide as an MMW view).
    const double span_m = 2.0 * pc.range_m * std::tan(pc.fov_rad / 2.0);
    const double lambda = 299792458.0 / (pc.frequency_ghz * 1e9);
    const double sigma = ir ? pc.ir_spread_mm / (1000.0 * span_m / s.width)
                            : 1.02 * lambda / pc.aperture_m * pc.range_m / (span_m / s.width) / 2.3548200450309493;
    const size_t taps = p.size();
    append_gaussian_taps(p, sigma, t.radius);
    const std::vector<double> psf(p.begin() + static_cast<std::ptrdiff_t>(taps), p.end());
    const auto append = [&](const std::vector<double>& v) {
      if (p.size() + v.size() > 0x7fffffffu) throw std::runtime_error("physics tables exceed 2^31 values");
      const int32_t at = static_cast<int32_t>(p.size());
      p.insert(p.end(), v.begin(), v.end());
      return at;
    };
    t.gauss = append(gauss_table());  // the sensor noise's table Gaussians
    if (ir) return t;
    // The MMW fast path's tables (kernels/physics_raw.cl).
    const int W = s.width, H = s.height, RW = m.raw_width, RH = m.raw_height;
    std::vector<double> wx, wy, cband, rband;
    axis_weights(W, RW, psf.data(), t.radius, wx, cband);
    axis_weights(H, RH, psf.data(), t.radius, wy, rband);
    t.wx = append(wx);
    t.wy = append(wy);
    t.cband = append(cband);
    t.rband = append(rband);
    t.display = append_display_tables(p, m, W, H, RW, RH);
    // Each subject's bare raw grid: wy . T . wx^T over its base image in kelvin.
    std::vector<double> bare(cat_.subjects.size() * size_t(RW) * RH, 0.0), rows(size_t(H) * RW);
    for (size_t subj = 0; subj < cat_.subjects.size(); ++subj) {
      const Image& base = assets_.bases[subj][view];
      const double gain = p[PS_PHYS_SUBJECTS + 2 * subj], offset = p[PS_PHYS_SUBJECTS + 2 * subj + 1];
      std::fill(rows.begin(), rows.end(), 0.0);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const double kelvin = gain * base.at(x, y) + offset;
          for (int c = int(cband[2 * x]); c <= int(cband[2 * x + 1]); ++c)
            rows[size_t(y) * RW + c] += wx[size_t(c) * W + x] * kelvin;
        }
      double* out = &bare[subj * size_t(RW) * RH];
      for (int y = 0; y < H; ++y)
        for (int r = int(rband[2 * y]); r <= int(rband[2 * y + 1]); ++r)
          for (int c = 0; c < RW; ++c) out[size_t(r) * RW + c] += wy[size_t(r) * H + y] * rows[size_t(y) * RW + c];
    }
    t.base = append(bare);
    return t;
  }

  // Block and region means of one pooled view into its columns of the feature rows.
  void pool(Kernels& K, const FeatureLayout& lay, size_t n, int slot, cl::Buffer& img, cl::Buffer& feats) {
    const int view = lay.pooled[slot];
    const Sensor& s = cat_.sensors[view];
    const int row_len = lay.image_features();
    int a = 0;
    K.pool_blocks.setArg(a++, img);
    K.pool_blocks.setArg(a++, static_cast<cl_uint>(n));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(s.width));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(s.height));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(lay.block));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(lay.blocks_x));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(lay.blocks_y));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(slot * lay.blocks_per_view()));
    K.pool_blocks.setArg(a++, static_cast<cl_int>(row_len));
    K.pool_blocks.setArg(a++, feats);
    rt_->queue().enqueueNDRangeKernel(K.pool_blocks, cl::NullRange, cl::NDRange(padded(n * lay.blocks_per_view())),
                                      cl::NDRange(kLocalSize));
    a = 0;
    K.pool_regions.setArg(a++, img);
    K.pool_regions.setArg(a++, static_cast<cl_uint>(n));
    K.pool_regions.setArg(a++, static_cast<cl_int>(s.width));
    K.pool_regions.setArg(a++, static_cast<cl_int>(s.height));
    K.pool_regions.setArg(a++, view_rects_[view]);
    K.pool_regions.setArg(a++, static_cast<cl_uint>(s.region_mask));
    K.pool_regions.setArg(a++, static_cast<cl_int>(lay.block_features()));
    K.pool_regions.setArg(a++, static_cast<cl_int>(row_len));
    K.pool_regions.setArg(a++, feats);
    rt_->queue().enqueueNDRangeKernel(K.pool_regions, cl::NullRange, cl::NDRange(padded(n * kRegions)),
                                      cl::NDRange(kLocalSize));
  }

  // A device view of host memory: PoCL on the CPU writes there directly.
  template <class T>
  cl::Buffer wrap(std::vector<T>& v) {
    return cl::Buffer(rt_->context(), CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, v.size() * sizeof(T), v.data());
  }
  // Makes the kernel's writes visible in host memory (a no-op copy where shared).
  template <class T>
  void sync(cl::Buffer& b, std::vector<T>& v) {
    const size_t bytes = v.size() * sizeof(T);
    void* p = rt_->queue().enqueueMapBuffer(b, CL_TRUE, CL_MAP_READ, 0, bytes);
    if (p != v.data()) std::memcpy(v.data(), p, bytes);
    rt_->queue().enqueueUnmapMemObject(b, p);
  }

  static std::string build_options(const Fidelity& f) {
    std::string o = f.precision == Precision::fp64      ? "-DPRECISION_FP64"
                    : f.precision == Precision::fixed16 ? "-DPRECISION_FIXED"
                                                        : "";
    if (f.fast_math) o += " -cl-fast-relaxed-math";
    return o;
  }

  Kernels& kernels_for(const Fidelity& f) {
    const std::string options = build_options(f);
    auto it = variants_.find(options);
    if (it != variants_.end()) return it->second;
    Kernels k;
    k.program = rt_->program(options);
    k.place = cl::Kernel(k.program, "place_view");
    k.render = cl::Kernel(k.program, "render_view");
    k.pool_blocks = cl::Kernel(k.program, "pool_blocks");
    k.pool_regions = cl::Kernel(k.program, "pool_regions");
    k.metal = cl::Kernel(k.program, "metal_zones");
    k.base_features = cl::Kernel(k.program, "base_features");
    k.footprint_deltas = cl::Kernel(k.program, "footprint_deltas");
    k.sparse_patterns = cl::Kernel(k.program, "sparse_patterns");
    k.features_sparse = cl::Kernel(k.program, "features_sparse");
    k.analytic_noise = cl::Kernel(k.program, "analytic_noise");
    k.fp64 = f.precision == Precision::fp64;
    k.real_bytes = k.fp64 ? sizeof(cl_double) : sizeof(cl_float);
    return variants_.emplace(options, std::move(k)).first->second;
  }
  // The sparse path's tables assume every pooled view has the first one's size.
  const Sensor& pooled_view(const FeatureLayout& lay) const { return cat_.sensors[lay.pooled.at(0)]; }
  int region_slot(const FeatureLayout& lay, int r) const {
    for (size_t slot = 0; slot < lay.pooled.size(); ++slot)
      if (cat_.sensors[lay.pooled[slot]].sees(r)) return static_cast<int>(slot);
    return 0;
  }

  struct RawGridTables {
    int count = 0;
    cl::Buffer first, cells, weights, columns;
    cl_int8 dims{};  // blocks_x, blocks_y, band_x, band_y, regions (RawGridNoise), the first block's column
    cl::Buffer noise, base_features, object_range, object_feature, object_value;
  };

  // Physics features-only (raw_grid_pooling.h): per pooled view, the raw grid of the
  // scenarios the tables do not cover (physics_raw, noise-free), then physics_features.
  void raw_grid_features(Kernels& K, const Plan& plan, size_t n, cl::Buffer& subject, cl::Buffer& objects,
                         cl_uint2 seed, cl_uint2 first, cl::Buffer& feats) {
    const FeatureLayout lay = FeatureLayout::of(cat_, plan.model.block);
    Plan quiet = plan;  // the raw grid without sensor noise: that is drawn per feature
    quiet.model.netd = 0;
    // Tables where objects stand at their places, and while the pairs' index (subjects x
    // (variants x regions)^2) stays small.
    const size_t combos = cat_.variant_list.size() * kRegions;
    const bool tabulated = plan.model.jitter <= 0 && !plan.model.transforms() &&
                           cat_.subjects.size() * combos * combos <= (size_t(1) << 26);
    cl::Context& ctx = rt_->context();
    for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
      const int view = lay.pooled[slot];
      RawGridTables& t = raw_grid_tables(K, quiet, lay, static_cast<int>(slot), tabulated);
      PsViewLaunch L{};
      render(K, quiet, view, n, subject, objects, seed, first, scratch_[view].at_least(ctx, 1), true, tabulated, &L);
      const cl::Buffer phys = physics_params(K, quiet, view, L);
      const auto& d = t.dims.s;
      const size_t per = PS_FEATURE_SPACE(size_t(d[0]), size_t(d[1]), size_t(d[2]), size_t(d[3]), size_t(d[4]));

      cl::Kernel& k = stage_kernel(K, "physics_features");
      int a = 0;
      k.setArg(a++, raw_.buf);
      k.setArg(a++, t.first);
      k.setArg(a++, t.cells);
      k.setArg(a++, t.weights);
      k.setArg(a++, t.columns);
      k.setArg(a++, static_cast<cl_int>(t.count));
      k.setArg(a++, static_cast<cl_int>(plan.model.raw_width * plan.model.raw_height));
      k.setArg(a++, phys);
      k.setArg(a++, static_cast<cl_int>(lay.image_features()));
      k.setArg(a++, feats);
      k.setArg(a++, sizeof(L), &L);
      k.setArg(a++, records_.buf);
      k.setArg(a++, subject);
      k.setArg(a++, objects);
      k.setArg(a++, t.base_features);
      k.setArg(a++, t.object_range);
      k.setArg(a++, t.object_feature);
      k.setArg(a++, t.object_value);
      set_param(K, k, a++, kernel_netd(plan));
      k.setArg(a++, t.dims);
      k.setArg(a++, t.noise);
      // Work spaces too large for private memory take global scratch, 64 MiB at most: a
      // launch per that many scenarios (the kernel indexes it from its launch's offset).
      const size_t chunk =
          per > PS_FEATURE_NOISE_PRIVATE
              ? std::max<size_t>(kLocalSize, (size_t(64) << 20) / (per * K.real_bytes) / kLocalSize * kLocalSize)
              : padded(n);
      cl::Buffer& scratch = features_scratch_.at_least(
          ctx, per > PS_FEATURE_NOISE_PRIVATE ? std::min(chunk, padded(n)) * per * K.real_bytes : 1);
      k.setArg(a++, scratch);
      for (size_t at = 0; at < n; at += chunk)
        rt_->queue().enqueueNDRangeKernel(k, cl::NDRange(at), cl::NDRange(std::min(chunk, padded(n) - at)),
                                          cl::NDRange(kLocalSize));
    }
  }

  // A pooled view's tables for physics_features, made once per (view, knobs, block, raw
  // grid, precision): the pooling taps, the noise factors and, when `tabulated`, each
  // subject's bare features and each (subject, variant, region)'s change to them, made by
  // physics_raw itself on one scenario per object (so a tabulated scenario differs from
  // its raw grid only in the order of float sums).
  RawGridTables& raw_grid_tables(Kernels& K, const Plan& quiet, const FeatureLayout& lay, int slot, bool tabulated) {
    const int view = lay.pooled[slot];
    const Sensor& sv = cat_.sensors[view];
    const ModelSettings& m = quiet.model;
    const int RW = m.raw_width, RH = m.raw_height, cells = RW * RH;
    char key[200];
    // Per program variant too (&K): tables made by another variant's arithmetic (fast math)
    // would make a run's features depend on what ran before it.
    std::snprintf(key, sizeof key, "%p %d %d %d %d %a %a %d %d", static_cast<const void*>(&K), view, lay.block, RW, RH,
                  m.illumination, m.worn_minutes, int(m.bilinear), int(tabulated));
    RawGridTables& t = raw_grid_tables_[key];
    if (t.first()) return t;
    cl::Context& ctx = rt_->context();
    const auto params = [&](const std::vector<double>& v) {
      return K.fp64 ? constant(ctx, v) : constant(ctx, std::vector<cl_float>(v.begin(), v.end()));
    };
    const RawGridPooling p = raw_grid_pooling(sv, lay, slot, RW, RH);
    t.count = static_cast<int>(p.columns.size());
    t.first = constant(ctx, p.first);
    t.cells = constant(ctx, p.cells);
    t.columns = constant(ctx, p.columns);
    t.weights = params(p.weights);
    const RawGridNoise z = raw_grid_noise(sv, lay, RW, RH);
    t.dims = {{z.blocks_x, z.blocks_y, z.band_x, z.band_y, z.regions, p.columns.empty() ? 0 : p.columns[0], 0, 0}};
    std::vector<double> noise = z.dx;
    for (const std::vector<double>* v : {&z.dy, &z.region_blocks, &z.region_own})
      noise.insert(noise.end(), v->begin(), v->end());
    t.noise = params(noise);
    const int S = static_cast<int>(cat_.subjects.size()), V = static_cast<int>(cat_.variant_list.size());
    std::vector<double> bare(static_cast<size_t>(S) * t.count, 0.0), values;
    const size_t combos = static_cast<size_t>(V) * kRegions;
    std::vector<cl_int2> object_range(S * combos + S * combos * combos, cl_int2{{0, 0}});  // [begin, end)
    std::vector<cl_int> features;
    if (tabulated) {
      // One scenario per subject bare, per (subject, variant, region seen) alone, and per
      // pair of those whose boxes meet.
      // A pair counts where its boxes meet on any subject (places move with the height).
      const auto meet = [&](int va, int ra, int vb, int rb) {
        const Image &a = assets_.sprite(sv.camera, va), &b = assets_.sprite(sv.camera, vb);
        for (int s = 0; s < S; ++s)
          if (boxes_meet(sprite_box(sv.place(s, ra), a), sprite_box(sv.place(s, rb), b))) return true;
        return false;
      };
      SceneBatch b;
      std::vector<std::array<int, 4>> pairs;  // va, ra, vb, rb with ra < rb
      for (int ra = 0; ra < kRegions; ++ra)
        for (int rb = ra + 1; rb < kRegions; ++rb)
          if (sv.sees(ra) && sv.sees(rb))
            for (int va = 0; va < V; ++va)
              for (int vb = 0; vb < V; ++vb)
                if (meet(va, ra, vb, rb)) pairs.push_back({va, ra, vb, rb});
      for (int s = 0; s < S; ++s) {
        Scenario sc;
        sc.subject = s;
        b.push(sc);
        for (int v = 0; v < V; ++v)
          for (int r = 0; r < kRegions; ++r)
            if (sv.sees(r)) {
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
      cl::Buffer subj = constant(ctx, b.subject), objs = constant(ctx, b.objects);
      render(K, quiet, view, N, subj, objs, {{0, 0}}, {{0, 0}}, scratch_[view].at_least(ctx, 1), true);
      std::vector<double> raw(N * cells);
      if (K.fp64) {
        rt_->queue().enqueueReadBuffer(raw_.buf, CL_TRUE, 0, N * cells * sizeof(cl_double), raw.data());
      } else {
        std::vector<cl_float> f(N * cells);
        rt_->queue().enqueueReadBuffer(raw_.buf, CL_TRUE, 0, N * cells * sizeof(cl_float), f.data());
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
          for (int r = 0; r < kRegions; ++r) {
            const size_t c = static_cast<size_t>(v) * kRegions + r;
            if (sv.sees(r)) {
              alone[c] = at++;
              entries(s * combos + c, {{alone[c], 1.0}, {bare_at, -1.0}});
            }
          }
        // Pairs: both together less each alone, plus the bare grid counted twice over.
        for (const auto& [va, ra, vb, rb] : pairs) {
          const size_t a = static_cast<size_t>(va) * kRegions + ra, c = static_cast<size_t>(vb) * kRegions + rb;
          entries(S * combos + (s * combos + a) * combos + c,
                  {{at++, 1.0}, {alone[a], -1.0}, {alone[c], -1.0}, {bare_at, 1.0}});
        }
      }
    }
    t.base_features = params(bare);
    t.object_range = constant(ctx, object_range);
    t.object_feature = constant(ctx, features);
    t.object_value = params(values);
    return t;
  }

  // Block-mean noise model: each mean gets N(0, sigma^2 / pixels) from the generator.
  void analytic_noise(Kernels& K, const Plan& plan, size_t n, cl_uint2 seed, cl_uint2 first, cl::Buffer& feats) {
    const FeatureLayout lay = FeatureLayout::of(cat_, plan.model.block);
    const Sensor& s = pooled_view(lay);
    cl::Kernel& k = K.analytic_noise;
    int a = 0;
    k.setArg(a++, feats);
    k.setArg(a++, region_rects_);
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, static_cast<cl_int>(s.width));
    k.setArg(a++, static_cast<cl_int>(s.height));
    k.setArg(a++, static_cast<cl_int>(lay.block));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_x));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_y));
    k.setArg(a++, static_cast<cl_int>(lay.pooled.size()));
    k.setArg(a++, static_cast<cl_int>(lay.image_features()));
    k.setArg(a++, static_cast<cl_float>(plan.model.pixel_sigma));
    k.setArg(a++, seed);
    k.setArg(a++, first);
    rt_->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(padded(n)), cl::NDRange(kLocalSize));
  }

  void build_sparse_tables(Kernels& K, const Plan& plan) {
    SparseTables& tables_ = K.tables;
    cl::Kernel& base_features_ = K.base_features;
    cl::Kernel& footprint_deltas_ = K.footprint_deltas;
    const ImagesConfig& ic = cat_.images;
    const FeatureLayout lay = FeatureLayout::of(cat_, plan.model.block);
    const Sensor& view = pooled_view(lay);
    const int block = plan.model.block, W = view.width, H = view.height, N = ic.noise_size;
    const bool noise = plan.model.pattern_noise;
    if (tables_.block == block && tables_.noise == noise) return;
    const int S = static_cast<int>(cat_.subjects.size()), V = static_cast<int>(cat_.variant_list.size());
    const int P = noise ? static_cast<int>(cat_.noise.size()) : 1;
    // A footprint per (variant, region, subject): the place moves with the subject's height.
    std::vector<cl_int> fps(static_cast<size_t>(V) * kRegions * S * PS_FP_LEN, 0);
    cl_int offset = 0;
    for (int v = 0; v < V; ++v)
      for (int r = 0; r < kRegions; ++r)
        for (int s = 0; s < S; ++s) {
          const Image& sp = assets_.sprite(Camera::mmw, v);
          const Rect box = sprite_box(cat_.sensors[lay.pooled[region_slot(lay, r)]].place(s, r), sp);
          cl_int* f = &fps[((static_cast<size_t>(v) * kRegions + r) * S + s) * PS_FP_LEN];
          f[PS_FP_SPRITE_X0] = box.x;
          f[PS_FP_SPRITE_Y0] = box.y;
          f[PS_FP_SPRITE_W] = box.w;
          f[PS_FP_SPRITE_H] = box.h;
          f[PS_FP_SPRITE_OFFSET] = mmw_sprites_[v].s[0];
          f[PS_FP_SPRITE_PADDED] = mmw_sprites_[v].s[3];
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
          if (x0 >= x1 || y0 >= y1) x0 = y0 = x1 = y1 = 0;  // wholly outside: touches nothing
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
          if (next > INT32_MAX)
            throw std::runtime_error("sparse feature tables exceed 2^31 entries; use --block larger");
          offset = static_cast<cl_int>(next);
        }
    cl::Context& ctx = rt_->context();
    cl::CommandQueue& q = rt_->queue();
    const int row_len = lay.image_features(), combos = V * kRegions * S * P;
    tables_.fps = constant(ctx, fps);
    tables_.deltas = cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, offset) * sizeof(cl_int));
    tables_.region_deltas = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(combos) * kRegions * sizeof(cl_int));
    tables_.base_sums = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(S) * row_len * sizeof(cl_int));
    tables_.base_means = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(S) * row_len * sizeof(cl_float));
    int a = 0;
    base_features_.setArg(a++, atlas_);
    base_features_.setArg(a++, bases_);
    base_features_.setArg(a++, region_rects_);
    base_features_.setArg(a++, pooled_);
    base_features_.setArg(a++, static_cast<cl_int>(lay.pooled.size()));
    base_features_.setArg(a++, static_cast<cl_int>(cat_.sensors.size()));
    base_features_.setArg(a++, region_slot_);
    base_features_.setArg(a++, static_cast<cl_int>(S));
    base_features_.setArg(a++, static_cast<cl_int>(W));
    base_features_.setArg(a++, static_cast<cl_int>(H));
    base_features_.setArg(a++, static_cast<cl_int>(block));
    base_features_.setArg(a++, static_cast<cl_int>(lay.blocks_x));
    base_features_.setArg(a++, static_cast<cl_int>(lay.blocks_y));
    base_features_.setArg(a++, static_cast<cl_int>(row_len));
    base_features_.setArg(a++, tables_.base_sums);
    base_features_.setArg(a++, tables_.base_means);
    q.enqueueNDRangeKernel(base_features_, cl::NullRange, cl::NDRange(padded(static_cast<size_t>(S) * row_len)),
                           cl::NDRange(kLocalSize));
    a = 0;
    footprint_deltas_.setArg(a++, atlas_);
    footprint_deltas_.setArg(a++, bases_);
    footprint_deltas_.setArg(a++, tables_.fps);
    footprint_deltas_.setArg(a++, noise_offsets_);
    footprint_deltas_.setArg(a++, noise_gains_);
    footprint_deltas_.setArg(a++, region_rects_);
    footprint_deltas_.setArg(a++, pooled_);
    footprint_deltas_.setArg(a++, static_cast<cl_int>(cat_.sensors.size()));
    footprint_deltas_.setArg(a++, region_slot_);
    footprint_deltas_.setArg(a++, static_cast<cl_int>(combos));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(S));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(P));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(W));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(block));
    set_param(K, footprint_deltas_, a++, ic.alpha);
    footprint_deltas_.setArg(a++, static_cast<cl_int>(N));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(noise ? 1 : 0));
    footprint_deltas_.setArg(a++, tables_.deltas);
    footprint_deltas_.setArg(a++, tables_.region_deltas);
    q.enqueueNDRangeKernel(footprint_deltas_, cl::NullRange, cl::NDRange(padded(combos)), cl::NDRange(kLocalSize));
    q.finish();
    tables_.block = block;
    tables_.noise = noise;
    tables_.patterns = P;
  }

  void sparse_features(Kernels& K, const Plan& plan, size_t n, cl::Buffer& subject, cl::Buffer& objects, cl_uint2 seed,
                       cl_uint2 first, cl::Buffer& feats) {
    build_sparse_tables(K, plan);
    const SparseTables& tables_ = K.tables;
    const ImagesConfig& ic = cat_.images;
    const FeatureLayout lay = FeatureLayout::of(cat_, plan.model.block);
    const Sensor& view = pooled_view(lay);
    const int row_len = lay.image_features();
    cl::Buffer& patterns = patterns_.at_least(rt_->context(), n * sizeof(cl_int));
    if (tables_.noise) {
      cl::Kernel& kp = K.sparse_patterns;
      kp.setArg(0, static_cast<cl_uint>(n));
      kp.setArg(1, static_cast<cl_int>(tables_.patterns));
      kp.setArg(2, seed);
      kp.setArg(3, first);
      kp.setArg(4, patterns);
      rt_->queue().enqueueNDRangeKernel(kp, cl::NullRange, cl::NDRange(padded(n)), cl::NDRange(kLocalSize));
    }
    cl::Kernel& k = K.features_sparse;
    int a = 0;
    k.setArg(a++, atlas_);
    k.setArg(a++, bases_);
    k.setArg(a++, tables_.fps);
    k.setArg(a++, tables_.deltas);
    k.setArg(a++, tables_.region_deltas);
    k.setArg(a++, tables_.base_sums);
    k.setArg(a++, tables_.base_means);
    k.setArg(a++, noise_offsets_);
    k.setArg(a++, noise_gains_);
    k.setArg(a++, region_rects_);
    k.setArg(a++, pooled_);
    k.setArg(a++, static_cast<cl_int>(lay.pooled.size()));
    k.setArg(a++, static_cast<cl_int>(cat_.sensors.size()));
    k.setArg(a++, region_slot_);
    k.setArg(a++, subject);
    k.setArg(a++, objects);
    k.setArg(a++, patterns);
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, static_cast<cl_int>(cat_.subjects.size()));
    k.setArg(a++, static_cast<cl_int>(tables_.patterns));
    k.setArg(a++, static_cast<cl_int>(view.width));
    k.setArg(a++, static_cast<cl_int>(view.height));
    k.setArg(a++, static_cast<cl_int>(lay.block));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_x));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_y));
    set_param(K, k, a++, ic.alpha);
    k.setArg(a++, static_cast<cl_int>(ic.noise_size));
    k.setArg(a++, static_cast<cl_int>(tables_.noise ? 1 : 0));
    k.setArg(a++, static_cast<cl_int>(row_len));
    k.setArg(a++, feats);
    rt_->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(padded(n)), cl::NDRange(kLocalSize));
  }

  const Catalogue& cat_;
  const AssetSet& assets_;
  std::shared_ptr<OpenCLRuntime> rt_;
  std::vector<cl_int4> mmw_sprites_;  // each variant's MMW sprite: atlas offset, width, height, padded offset
  std::map<std::string, Kernels> variants_;
  cl::Buffer atlas_, bases_, sprites_, places_, noise_offsets_, noise_gains_, pooled_, region_slot_, region_rects_,
      influence_, categories_, base_zones_, metal_zone_rec_, metal_region_rec_, metal_tensors_;
  const Sensor* metal_view_ = nullptr;  // the first MMW view: the metal model's pixel scale
  std::vector<cl::Buffer> view_rects_;  // per view: int4 per region
  Grown subject_, objects_, patterns_, metal_out_, field_, records_, raw_, view_scratch_, physics_none_,
      features_scratch_;
  std::map<std::string, PhysicsTables> physics_tables_;
  std::map<std::string, RawGridTables> raw_grid_tables_;  // per (view, block, raw grid, precision)
  std::vector<Grown> scratch_;                            // per view: images only pooled
};

}  // namespace

std::unique_ptr<Backend> make_opencl_backend(const Catalogue& cat, const AssetSet& assets,
                                             std::shared_ptr<OpenCLRuntime> runtime) {
  return std::make_unique<OpenCLBackend>(cat, assets, std::move(runtime));
}

}  // namespace portalsim
