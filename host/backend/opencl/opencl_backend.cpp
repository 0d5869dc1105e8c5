// The OpenCL backend: per batch, the features path whose gate applies to every pooled view
// (else each pooled view rendered and pooled), each camera view the plan needs rendered by
// the first view path whose gate applies (else the stage chain), then the metal zones.
// The paths are in paths/; docs/dev/architecture.md says how they fit.
#include "backend/opencl/opencl_backend.h"

#include <algorithm>

#include "backend/opencl/paths/paths.h"
#include "backend/stages.h"

namespace portalsim {

namespace {

using namespace opencl;

class OpenCLBackend final : public Backend {
 public:
  OpenCLBackend(const Catalogue& cat, const AssetSet& assets, std::shared_ptr<OpenCLRuntime> rt)
      : cat_(cat),
        assets_(assets),
        rt_(std::move(rt)),
        device_(cat, assets, *rt_),
        kernels_(*rt_, KernelCounts::of(cat)),
        metal_(device_) {
    for (const Sensor& s : cat.sensors) check_chain(s);
#define PORTALSIM_OPEN_FEATURE_PATH(name) features_paths_.push_back(name##_path(device_));
    PORTALSIM_FEATURE_PATHS(PORTALSIM_OPEN_FEATURE_PATH)
#undef PORTALSIM_OPEN_FEATURE_PATH
  }

  std::string name() const override { return "opencl"; }

  std::unique_ptr<Backend> for_catalogue(const Catalogue& cat, const AssetSet& assets) const override {
    return std::make_unique<OpenCLBackend>(cat, assets, rt_);
  }

  void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) override {
    if (drawn_grids(plan))
      run_by_raw_grid(batch, plan, out);
    else
      run_part(batch, plan, out, true);
  }

  // No gate reads the raw grid (RawGridDrawn.NoGateReadsTheGrid), so a run whose grid is
  // drawn takes its first grid's paths, every part alike.
  std::vector<std::string> paths(const Plan& plan) const override {
    const Route r = route(plan, FeatureLayout::of(cat_, plan.model.block));
    std::vector<std::string> taken;
    for (size_t k = 0; k < cat_.sensors.size(); ++k)
      if (r.views[k].path)
        taken.push_back(cat_.sensors[k].name + ": " + describe(r.views[k].path->name(), r.views[k].gate));
    if (plan.features)
      taken.push_back(r.features ? "features: " + describe(r.features->name(), r.features_gate)
                                 : std::string("features: ") + kPooledFeatures);
    return taken;
  }

  std::vector<int> rendered_views(const Plan& plan) const override {
    const Route r = route(plan, FeatureLayout::of(cat_, plan.model.block));
    std::vector<int> views;
    for (size_t k = 0; k < cat_.sensors.size(); ++k)
      if (r.views[k].path) views.push_back(static_cast<int>(k));
    return views;
  }

 private:
  static bool drawn_grids(const Plan& plan) {
    return plan.model.model == Model::physics && plan.model.raw_grid_drawn();
  }
  // `plan` with its raw grid fixed at `grid`: what a grid's part of a batch runs under.
  static Plan part_plan(const Plan& plan, const std::array<int, 2>& grid) {
    Plan one = plan;
    one.annotations = false;
    one.model.raw_grids.clear();
    one.model.raw_width = grid[0];
    one.model.raw_height = grid[1];
    return one;
  }

  // A raw grid drawn per scenario: every kernel of a batch takes one grid's shapes and
  // tables, so each grid's scenarios run as a part of their own (their indices in a table,
  // SceneBatch::indices) under the plan with that grid fixed, and their rows are put back in
  // the batch's order. The annotations do not depend on the grid: made once, for the batch.
  void run_by_raw_grid(const SceneBatch& batch, const Plan& plan, BatchOutput& out) {
    const size_t n = batch.size();
    prepare_output(out, cat_, plan, n);
    const std::vector<std::array<int, 2>>& grids = plan.model.raw_grids;
    device_.derived.hold_parts(grids.size());
    std::vector<std::vector<size_t>> rows(grids.size());
    for (size_t i = 0; i < n; ++i) {
      const auto g = std::find(grids.begin(), grids.end(), raw_grid_at(plan.model, batch.index_of(i)));
      rows[static_cast<size_t>(g - grids.begin())].push_back(i);
    }
    for (size_t g = 0; g < grids.size(); ++g) {
      if (rows[g].empty()) continue;
      SceneBatch part(batch.regions);
      part.first_index = batch.index_of(rows[g][0]);
      for (const size_t i : rows[g]) {
        part.push(batch.at(i));
        part.indices.push_back(batch.index_of(i));
      }
      run_part(part, part_plan(plan, grids[g]), part_out_, false);
      place_rows(out, part_out_, rows[g]);
    }
    annotations(cat_, assets_, batch, plan, out);
  }

  // `batch` under `plan`, whose raw grid is one; with_annotations: the plan's annotations too.
  void run_part(const SceneBatch& batch, const Plan& plan, BatchOutput& out, bool with_annotations) {
    const size_t n = batch.size();
    prepare_output(out, cat_, plan, n);
    if (n == 0) {
      if (with_annotations) annotations(cat_, assets_, batch, plan, out);
      return;
    }
    const FeatureLayout& lay = out.layout;
    cl::Context& ctx = rt_->context();
    cl::CommandQueue& q = rt_->queue();
    Kernels& K = kernels_(plan.fidelity);
    DeviceBatch b{.n = n,
                  .subject = subject_.at_least(ctx, n),
                  .objects = objects_.at_least(ctx, n * cat_.regions.size() * sizeof(int16_t)),
                  .seed = split(plan.model.seed),
                  .first = split(batch.first_index),
                  .indices = {},
                  .variants = std::vector<char>(cat_.variant_list.size(), 0)};
    if (!batch.indices.empty()) {
      b.indices = indices_.at_least(ctx, n * sizeof(cl_ulong));
      q.enqueueWriteBuffer(b.indices, CL_FALSE, 0, n * sizeof(cl_ulong), batch.indices.data());
    }
    for (int16_t v : batch.objects)
      if (v != kNoObject) b.variants[static_cast<size_t>(v)] = 1;
    q.enqueueWriteBuffer(b.subject, CL_FALSE, 0, n, batch.subject.data());
    q.enqueueWriteBuffer(b.objects, CL_FALSE, 0, n * cat_.regions.size() * sizeof(int16_t), batch.objects.data());

    // Features are written straight into the caller's rows, as kept images are.
    const Route r = route(plan, lay);
    cl::Buffer feats;
    if (plan.features) feats = wrap(ctx, out.features);
    if (r.features) r.features->features(K, plan, r.features_gate, b, feats);

    // Each camera view the plan needs: rendered into the caller's buffer when its images
    // are kept (PoCL on the CPU writes there directly), else into a device buffer that
    // only pooling reads.
    const bool pooling = plan.features && !r.features;
    std::vector<cl::Buffer> rendered(cat_.sensors.size());
    for (size_t k = 0; k < cat_.sensors.size(); ++k) {
      const ViewRoute& vr = r.views[k];
      if (!vr.path) continue;
      const int view = static_cast<int>(k);
      rendered[k] = plan.image(view) ? wrap(ctx, out.views[k].pixels)
                                     : device_.pooled_only[k].at_least(ctx, n * cat_.sensors[k].pixels());
      ViewLaunch v(device_, K, plan, view, b, rendered[k], vr.path->uses_field());
      v.run("place_view", n);  // one placement record per scenario, read by every row after
      vr.path->render(v, vr.gate);
    }
    if (pooling)
      for (size_t slot = 0; slot < lay.pooled.size(); ++slot)
        pool_view(device_, K, lay, b, static_cast<int>(slot), rendered[lay.pooled[slot]], feats);
    if (plan.features && plan.model.pixel_sigma_hi() > 0 && !plan.pixel_noise_per_pixel())
      block_mean_noise(device_, K, plan, b, feats);
    // The host's boxes and masks while PoCL's threads run what is queued (their outputs
    // are apart); the maps below wait for the kernels.
    q.flush();
    if (with_annotations) annotations(cat_, assets_, batch, plan, out);
    if (plan.features) sync(q, feats, out.features);
    for (size_t k = 0; k < cat_.sensors.size(); ++k)
      if (plan.image(static_cast<int>(k))) sync(q, rendered[k], out.views[k].pixels);
    if (plan.metal) metal_.run(K, plan, b, out);
    q.finish();
  }

  // Every choice of paths run() makes for `plan`, made here alone: the features path, and
  // for each view that is rendered, its path (null: the view is not rendered).
  struct Route {
    FeaturePath* features = nullptr;  // null: the rendered views are pooled
    Gate features_gate;
    std::vector<ViewRoute> views;
  };
  Route route(const Plan& plan, const FeatureLayout& lay) const {
    Route r;
    // The first features path whose gate applies to every pooled view.
    // (the first pooled view's gate gives the variant).
    if (plan.features && !lay.pooled.empty())
      for (const auto& p : features_paths_) {
        const Gate g = p->gate(plan, cat_.sensors[lay.pooled[0]]);
        bool all = g.runs;
        for (size_t slot = 1; slot < lay.pooled.size(); ++slot)
          all = all && p->applies(plan, cat_.sensors[lay.pooled[slot]]);
        if (all) {
          r.features = p.get();
          r.features_gate = g;
          break;
        }
      }
    const bool pooling = plan.features && !r.features;
    r.views.resize(cat_.sensors.size());
    for (size_t k = 0; k < cat_.sensors.size(); ++k) {
      const Sensor& s = cat_.sensors[k];
      if (plan.image(static_cast<int>(k)) || (pooling && s.pooled)) r.views[k] = view_route(plan, s);
    }
    return r;
  }

  const Catalogue& cat_;
  const AssetSet& assets_;
  std::shared_ptr<OpenCLRuntime> rt_;
  Device device_;
  KernelVariants kernels_;
  MetalPath metal_;
  std::vector<std::unique_ptr<FeaturePath>> features_paths_;  // in the order they are tried
  Grown subject_, objects_, indices_;
  BatchOutput part_out_;  // a raw grid's part of a batch (run_by_raw_grid)
};

}  // namespace

std::unique_ptr<Backend> make_opencl_backend(const Catalogue& cat, const AssetSet& assets,
                                             std::shared_ptr<OpenCLRuntime> runtime) {
  return std::make_unique<OpenCLBackend>(cat, assets, std::move(runtime));
}

}  // namespace portalsim
