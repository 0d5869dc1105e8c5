#include "backend/opencl/opencl_backend.h"

#include <cmath>
#include <cstring>

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

class OpenCLBackend final : public Backend {
 public:
  OpenCLBackend(const Catalogue& cat, const AssetSet& assets, std::shared_ptr<OpenCLRuntime> rt)
      : cat_(cat), assets_(assets), rt_(std::move(rt)) {
    std::vector<uint8_t> atlas;
    auto add = [&](const Image& img) {
      const int off = static_cast<int>(atlas.size());
      atlas.insert(atlas.end(), img.pixels.begin(), img.pixels.end());
      return off;
    };
    std::vector<cl_int> bases;
    for (const auto& views : assets.bases)
      for (const Image& img : views) bases.push_back(add(img));
    const size_t V = cat.variant_list.size();
    std::vector<cl_int4> sprites(V * 2), places(V * kRegions);
    for (size_t v = 0; v < V; ++v) {
      const Image* sp[2] = {&assets.mmw_sprites[v], &assets.ir_sprites[v]};
      for (int s = 0; s < 2; ++s) sprites[v * 2 + s] = {{add(*sp[s]), sp[s]->width, sp[s]->height, 0}};
      for (int r = 0; r < kRegions; ++r) {
        const Region& reg = cat.regions[r];
        // Sprite centred in the region; >> 1 floors negative differences too.
        places[v * kRegions + r] = {
            {reg.mmw.x + ((reg.mmw.w - sp[0]->width) >> 1), reg.mmw.y + ((reg.mmw.h - sp[0]->height) >> 1),
             reg.ir.x + ((reg.ir.w - sp[1]->width) >> 1), reg.ir.y + ((reg.ir.h - sp[1]->height) >> 1)}};
      }
    }
    std::vector<cl_int> noise_offsets;
    std::vector<cl_float> noise_gains;
    for (const auto& sp : sprites) sprite_offsets_.push_back(sp.s[0]);
    for (size_t k = 0; k < assets.noise.size(); ++k) {
      noise_offsets.push_back(add(assets.noise[k]));
      noise_gains.push_back(static_cast<float>(cat.noise[k].gain));
    }
    if (atlas.size() > 0x7fffffffu) throw std::runtime_error("catalogue images exceed 2 GiB");
    std::vector<cl_int4> rects;
    for (const Region& r : cat.regions) rects.push_back({{r.mmw.x, r.mmw.y, r.mmw.w, r.mmw.h}});
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
    rects_ = constant(ctx, rects);
    influence_ = constant(ctx, influence);
    categories_ = constant(ctx, categories);
    base_zones_ = constant(ctx, base_zones);
  }

  std::string name() const override { return "opencl"; }

  void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) override {
    const ImagesConfig& ic = cat_.images;
    const size_t n = batch.size();
    prepare_output(out, cat_, plan, n);
    const size_t mmw_px = static_cast<size_t>(ic.mmw_width) * ic.mmw_height;
    const int row_len = out.layout.image_features();
    if (n == 0) return;

    cl::Context& ctx = rt_->context();
    cl::CommandQueue& q = rt_->queue();
    Kernels& K = kernels_for(plan.fidelity);
    cl::Buffer& subject = subject_.at_least(ctx, n);
    cl::Buffer& objects = objects_.at_least(ctx, n * kRegions * sizeof(int16_t));
    q.enqueueWriteBuffer(subject, CL_FALSE, 0, n, batch.subject.data());
    q.enqueueWriteBuffer(objects, CL_FALSE, 0, n * kRegions * sizeof(int16_t), batch.objects.data());
    const cl_uint2 seed = split(plan.model.seed), first = split(batch.first_index);
    const cl_uint count = static_cast<cl_uint>(n);
    const cl_int flags = (plan.model.pattern_noise ? 1 : 0) | (plan.pixel_noise_per_pixel() ? 2 : 0);

    auto render = [&](int view, cl::Buffer& dst, int W, int H) {
      cl::Kernel& k = K.render;
      int a = 0;
      k.setArg(a++, atlas_);
      k.setArg(a++, bases_);
      k.setArg(a++, sprites_);
      k.setArg(a++, places_);
      k.setArg(a++, noise_offsets_);
      k.setArg(a++, noise_gains_);
      k.setArg(a++, subject);
      k.setArg(a++, objects);
      k.setArg(a++, count);
      k.setArg(a++, static_cast<cl_int>(view));
      k.setArg(a++, static_cast<cl_int>(W));
      k.setArg(a++, static_cast<cl_int>(H));
      set(k, a++, param(K, ic.alpha));
      k.setArg(a++, seed);
      k.setArg(a++, first);
      k.setArg(a++, static_cast<cl_int>(cat_.noise.size()));
      k.setArg(a++, static_cast<cl_int>(ic.noise_size));
      set(k, a++, param(K, plan.model.pixel_sigma));
      k.setArg(a++, flags);
      // Jitter in this view's pixels: the IR view is at its own scale.
      const double sx = view == 2 ? double(ic.ir_width) / ic.mmw_width : 1.0;
      const double sy = view == 2 ? double(ic.ir_height) / (2.0 * ic.mmw_height) : 1.0;
      k.setArg(a++, static_cast<cl_int>(plan.model.bilinear ? 1 : 0));
      k.setArg(a++, static_cast<cl_float>(plan.model.jitter * sx));
      k.setArg(a++, static_cast<cl_float>(plan.model.jitter * sy));
      k.setArg(a++, dst);
      q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(padded(n * H)), cl::NDRange(kLocalSize));
    };

    cl::Buffer& feats = features_.at_least(ctx, std::max<size_t>(1, n * row_len * sizeof(float)));
    if (plan.sparse_features()) {
      sparse_features(K, plan, n, subject, objects, seed, first, feats);
    } else if (plan.renders_mmw()) {
      // Images the caller keeps are written in place (no copy back on a CPU device);
      // images only pooled live in device buffers.
      cl::Buffer upper = plan.mmw_images ? wrap(out.upper) : upper_.at_least(ctx, n * mmw_px);
      cl::Buffer lower = plan.mmw_images ? wrap(out.lower) : lower_.at_least(ctx, n * mmw_px);
      render(0, upper, ic.mmw_width, ic.mmw_height);
      render(1, lower, ic.mmw_width, ic.mmw_height);
      if (plan.features) {
        const FeatureLayout& f = out.layout;
        int a = 0;
        K.pool_blocks.setArg(a++, upper);
        K.pool_blocks.setArg(a++, lower);
        K.pool_blocks.setArg(a++, count);
        K.pool_blocks.setArg(a++, static_cast<cl_int>(ic.mmw_width));
        K.pool_blocks.setArg(a++, static_cast<cl_int>(ic.mmw_height));
        K.pool_blocks.setArg(a++, static_cast<cl_int>(f.block));
        K.pool_blocks.setArg(a++, static_cast<cl_int>(f.blocks_x));
        K.pool_blocks.setArg(a++, static_cast<cl_int>(f.blocks_y));
        K.pool_blocks.setArg(a++, static_cast<cl_int>(row_len));
        K.pool_blocks.setArg(a++, feats);
        q.enqueueNDRangeKernel(K.pool_blocks, cl::NullRange, cl::NDRange(padded(n * 2 * f.blocks_x * f.blocks_y)),
                               cl::NDRange(kLocalSize));
        a = 0;
        K.pool_regions.setArg(a++, upper);
        K.pool_regions.setArg(a++, lower);
        K.pool_regions.setArg(a++, count);
        K.pool_regions.setArg(a++, static_cast<cl_int>(ic.mmw_width));
        K.pool_regions.setArg(a++, static_cast<cl_int>(ic.mmw_height));
        K.pool_regions.setArg(a++, rects_);
        K.pool_regions.setArg(a++, static_cast<cl_int>(2 * f.blocks_x * f.blocks_y));
        K.pool_regions.setArg(a++, static_cast<cl_int>(row_len));
        K.pool_regions.setArg(a++, feats);
        q.enqueueNDRangeKernel(K.pool_regions, cl::NullRange, cl::NDRange(padded(n * kRegions)),
                               cl::NDRange(kLocalSize));
      }
      if (plan.mmw_images) {
        sync(upper, out.upper);
        sync(lower, out.lower);
      }
    }
    if (plan.features) {
      if (plan.model.pixel_sigma > 0 && !plan.pixel_noise_per_pixel()) analytic_noise(K, plan, n, seed, first, feats);
      q.enqueueReadBuffer(feats, CL_FALSE, 0, n * row_len * sizeof(float), out.features.data());
    }
    if (plan.ir_image) {
      cl::Buffer ir = wrap(out.ir);
      render(2, ir, ic.ir_width, ic.ir_height);
      sync(ir, out.ir);
    }
    if (plan.metal) {
      cl::Buffer& metal = metal_out_.at_least(ctx, n * kZones);
      int a = 0;
      K.metal.setArg(a++, influence_);
      K.metal.setArg(a++, categories_);
      K.metal.setArg(a++, base_zones_);
      K.metal.setArg(a++, subject);
      K.metal.setArg(a++, objects);
      K.metal.setArg(a++, count);
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
  // A device view of host memory: PoCL on the CPU writes there directly.
  cl::Buffer wrap(std::vector<uint8_t>& v) {
    return cl::Buffer(rt_->context(), CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, v.size(), v.data());
  }
  // Makes the kernel's writes visible in host memory (a no-op copy where shared).
  void sync(cl::Buffer& b, std::vector<uint8_t>& v) {
    void* p = rt_->queue().enqueueMapBuffer(b, CL_TRUE, CL_MAP_READ, 0, v.size());
    if (p != v.data()) std::memcpy(v.data(), p, v.size());
    rt_->queue().enqueueUnmapMemObject(b, p);
  }

  // The tables of the sparse features path, built once per (block, pattern noise) for
  // each program variant.
  struct SparseTables {
    int block = -1;
    bool noise = false;
    int patterns = 1;
    cl::Buffer fps, deltas, region_deltas, base_sums, base_means;
  };
  // The kernels of one program variant (precision, fast math).
  struct Kernels {
    cl::Kernel render, pool_blocks, pool_regions, metal, base_features, footprint_deltas, features_sparse,
        analytic_noise;
    SparseTables tables;
    bool fp64 = false;  // alpha and sigma are passed as double
  };

  // A model parameter at the kernels' parameter precision (see kernels/precision.cl).
  struct ParamArg {
    bool fp64;
    double v;
  };
  static ParamArg param(const Kernels& k, double v) { return {k.fp64, v}; }
  static void set(cl::Kernel& k, int index, ParamArg p) {
    if (p.fp64)
      k.setArg(index, static_cast<cl_double>(p.v));
    else
      k.setArg(index, static_cast<cl_float>(p.v));
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
    cl::Program& p = rt_->program(options);
    Kernels k;
    k.render = cl::Kernel(p, "render_view");
    k.pool_blocks = cl::Kernel(p, "pool_blocks");
    k.pool_regions = cl::Kernel(p, "pool_regions");
    k.metal = cl::Kernel(p, "metal_zones");
    k.base_features = cl::Kernel(p, "base_features");
    k.footprint_deltas = cl::Kernel(p, "footprint_deltas");
    k.features_sparse = cl::Kernel(p, "features_sparse");
    k.analytic_noise = cl::Kernel(p, "analytic_noise");
    k.fp64 = f.precision == Precision::fp64;
    return variants_.emplace(options, std::move(k)).first->second;
  }

  // Block-mean noise model: each mean gets N(0, sigma^2 / pixels) from the generator.
  void analytic_noise(Kernels& K, const Plan& plan, size_t n, cl_uint2 seed, cl_uint2 first, cl::Buffer& feats) {
    const ImagesConfig& ic = cat_.images;
    const FeatureLayout lay = FeatureLayout::of(cat_, plan.model.block);
    cl::Kernel& k = K.analytic_noise;
    int a = 0;
    k.setArg(a++, feats);
    k.setArg(a++, rects_);
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, static_cast<cl_int>(ic.mmw_width));
    k.setArg(a++, static_cast<cl_int>(ic.mmw_height));
    k.setArg(a++, static_cast<cl_int>(lay.block));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_x));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_y));
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
    const int block = plan.model.block, W = ic.mmw_width, H = ic.mmw_height, N = ic.noise_size;
    const bool noise = plan.model.pattern_noise;
    if (tables_.block == block && tables_.noise == noise) return;
    const int S = static_cast<int>(cat_.subjects.size()), V = static_cast<int>(cat_.variant_list.size());
    const int P = noise ? static_cast<int>(cat_.noise.size()) : 1;
    std::vector<cl_int> fps(static_cast<size_t>(V) * kRegions * 16, 0);
    cl_int offset = 0;
    for (int v = 0; v < V; ++v)
      for (int r = 0; r < kRegions; ++r) {
        const Image& sp = assets_.mmw_sprites[v];
        const Rect& rc = cat_.regions[r].mmw;
        cl_int* f = &fps[(static_cast<size_t>(v) * kRegions + r) * 16];
        f[0] = rc.x + ((rc.w - sp.width) >> 1);
        f[1] = rc.y + ((rc.h - sp.height) >> 1);
        f[2] = sp.width;
        f[3] = sp.height;
        f[4] = sprite_offsets_[v * 2];
        f[5] = f[0] + (sp.width >> 1) - (N >> 1);
        f[6] = f[1] + (sp.height >> 1) - (N >> 1);
        int x0 = f[0], y0 = f[1], x1 = f[0] + f[2], y1 = f[1] + f[3];
        if (noise) {
          x0 = std::min(x0, f[5]);
          y0 = std::min(y0, f[6]);
          x1 = std::max(x1, f[5] + N);
          y1 = std::max(y1, f[6] + N);
        }
        x0 = std::max(x0, 0);
        y0 = std::max(y0, 0);
        x1 = std::min(x1, W);
        y1 = std::min(y1, H);
        if (x0 >= x1 || y0 >= y1) x0 = y0 = x1 = y1 = 0;  // wholly outside: touches nothing
        f[7] = x0;
        f[8] = y0;
        f[9] = x1;
        f[10] = y1;
        f[11] = x0 / block;
        f[12] = y0 / block;
        f[13] = x1 > x0 ? (x1 - 1) / block - f[11] + 1 : 0;
        f[14] = y1 > y0 ? (y1 - 1) / block - f[12] + 1 : 0;
        f[15] = offset;
        const int64_t next = offset + static_cast<int64_t>(S) * P * f[13] * f[14];
        if (next > INT32_MAX) throw std::runtime_error("sparse feature tables exceed 2^31 entries; use --block larger");
        offset = static_cast<cl_int>(next);
      }
    cl::Context& ctx = rt_->context();
    cl::CommandQueue& q = rt_->queue();
    const FeatureLayout lay = FeatureLayout::of(cat_, block);
    const int row_len = lay.image_features(), combos = V * kRegions * S * P;
    tables_.fps = constant(ctx, fps);
    tables_.deltas = cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, offset) * sizeof(cl_int));
    tables_.region_deltas = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(combos) * kRegions * sizeof(cl_int));
    tables_.base_sums = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(S) * row_len * sizeof(cl_int));
    tables_.base_means = cl::Buffer(ctx, CL_MEM_READ_WRITE, static_cast<size_t>(S) * row_len * sizeof(cl_float));
    int a = 0;
    base_features_.setArg(a++, atlas_);
    base_features_.setArg(a++, bases_);
    base_features_.setArg(a++, rects_);
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
    footprint_deltas_.setArg(a++, rects_);
    footprint_deltas_.setArg(a++, static_cast<cl_int>(combos));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(S));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(P));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(W));
    footprint_deltas_.setArg(a++, static_cast<cl_int>(block));
    set(footprint_deltas_, a++, param(K, ic.alpha));
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
    const int row_len = lay.image_features();
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
    k.setArg(a++, rects_);
    k.setArg(a++, subject);
    k.setArg(a++, objects);
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, static_cast<cl_int>(cat_.subjects.size()));
    k.setArg(a++, static_cast<cl_int>(tables_.patterns));
    k.setArg(a++, static_cast<cl_int>(ic.mmw_width));
    k.setArg(a++, static_cast<cl_int>(ic.mmw_height));
    k.setArg(a++, static_cast<cl_int>(lay.block));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_x));
    k.setArg(a++, static_cast<cl_int>(lay.blocks_y));
    set(k, a++, param(K, ic.alpha));
    k.setArg(a++, static_cast<cl_int>(ic.noise_size));
    k.setArg(a++, static_cast<cl_int>(tables_.noise ? 1 : 0));
    k.setArg(a++, seed);
    k.setArg(a++, first);
    k.setArg(a++, static_cast<cl_int>(row_len));
    k.setArg(a++, feats);
    rt_->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(padded(n)), cl::NDRange(kLocalSize));
  }

  const Catalogue& cat_;
  const AssetSet& assets_;
  std::shared_ptr<OpenCLRuntime> rt_;
  std::vector<cl_int> sprite_offsets_;
  std::map<std::string, Kernels> variants_;
  cl::Buffer atlas_, bases_, sprites_, places_, noise_offsets_, noise_gains_, rects_, influence_, categories_,
      base_zones_;
  Grown subject_, objects_, upper_, lower_, metal_out_, features_;
};

}  // namespace

std::unique_ptr<Backend> make_opencl_backend(const Catalogue& cat, const AssetSet& assets,
                                             std::shared_ptr<OpenCLRuntime> runtime) {
  return std::make_unique<OpenCLBackend>(cat, assets, std::move(runtime));
}

}  // namespace portalsim
