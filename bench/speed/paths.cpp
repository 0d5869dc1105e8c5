#include "speed/paths.h"

#include <algorithm>
#include <stdexcept>

#include "base/error.h"
#include "base/parallel.h"
#include "baseline.h"
#include "scene/generator.h"

namespace portalsim::speed {

Plan features_plan() {
  Plan p;
  p.images = 0;
  p.metal = false;
  return p;
}

Plan images_plan(double sigma) {
  Plan p;
  p.features = false;
  p.metal = false;
  p.model.pixel_sigma = sigma;
  return p;
}

std::vector<SpeedPath> speed_paths() {
  std::vector<SpeedPath> paths;
  auto add = [&](std::string key, std::string title, RunSpec spec, Plan kernel) {
    spec.seed = 1;
    // The kernels' plan takes the run's model and tier (spec.settings()); what is kept
    // is the path's own.
    const Plan settings = spec.settings();
    kernel.model = settings.model;
    kernel.fidelity = settings.fidelity;
    SpeedPath p{std::move(key), std::move(title), std::move(spec), kernel};
    p.has_loop = p.kernel.model.model == Model::thesis;
    p.needs_fp64_end_to_end = p.kernel.model.model == Model::physics;
    paths.push_back(std::move(p));
  };
  RunSpec features;
  features.what = "features";
  features.formats = {"npy"};
  Plan fp = features_plan();
  add("features", "features-only (thesis, sparse, block 10; end to end: .npy)", features, fp);
  RunSpec images;
  images.what = "images";  // PNG image folders, generate's default image output
  add("images", "images, three views (end to end: PNG folders)", images, images_plan(0));
  RunSpec noisy = images;
  noisy.set_knob_text("pixel_noise", "2", "portalsim bench");
  add("noisy_images", "images with pixel noise, sigma 2", noisy, images_plan(2));
  RunSpec physics = images;
  physics.set_knob_text("model", "physics", "portalsim bench");
  add("physics_images", "images, physics model", physics, images_plan(0));
  RunSpec annotated = images;
  annotated.annotations = true;
  Plan ap = images_plan(0);
  ap.annotations = true;
  add("annotations", "images with boxes and instance masks", annotated, ap);
  return paths;
}

std::vector<SpeedPath> chosen_paths(const std::vector<std::string>& keys) {
  const std::vector<SpeedPath> all = speed_paths();
  for (const std::string& key : keys)
    if (std::none_of(all.begin(), all.end(), [&](const SpeedPath& p) { return p.key == key; })) {
      std::string names;
      for (const SpeedPath& p : all) names += (names.empty() ? "" : ", ") + p.key;
      throw InputError("--paths: \"" + key + "\" is not one of " + names);
    }
  std::vector<SpeedPath> chosen;
  for (const SpeedPath& p : all)
    if (keys.empty() || std::find(keys.begin(), keys.end(), p.key) != keys.end()) chosen.push_back(p);
  return chosen;
}

SceneBatch make_batch(const Catalogue& cat, size_t n, int max_objects) {
  GeneratorSpec spec;
  spec.max_objects = max_objects;
  Generator gen(cat, spec, 1);
  SceneBatch b(cat.region_count());
  for (size_t i = 0; i < n; ++i) b.push(gen(i));
  return b;
}

double output_bytes_per_scenario(const BatchOutput& out) {
  if (out.n == 0) return 0;
  double bytes = static_cast<double>(out.metal.size()) + sizeof(float) * static_cast<double>(out.features.size());
  for (const ViewImages& v : out.views) bytes += static_cast<double>(v.pixels.size());
  return bytes / static_cast<double>(out.n);
}

struct Loop::Impl {
  const Catalogue& cat;
  const AssetSet& assets;
  Plan plan;
  std::unique_ptr<baseline::SparseFeatures> features;
  std::unique_ptr<Annotator> annotator;
};

Loop::Loop(const Catalogue& cat, const AssetSet& assets, const SpeedPath& path)
    : impl_(std::make_unique<Impl>(Impl{cat, assets, path.kernel, nullptr, nullptr})) {
  if (!path.has_loop) throw std::logic_error("the path " + path.key + " has no plain loop");
  if (path.kernel.images == 0)
    impl_->features = std::make_unique<baseline::SparseFeatures>(cat, assets, path.kernel.model);
  if (path.kernel.annotations) impl_->annotator = std::make_unique<Annotator>(cat, assets);
}

Loop::~Loop() = default;

void Loop::run(const SceneBatch& batch, BatchOutput& out) {
  Impl& m = *impl_;
  if (m.features) {
    m.features->run(batch, out);
    return;
  }
  baseline::render_images(m.cat, m.assets, batch, m.plan.model, out);
  // As Backend::annotations does it, on as many threads.
  if (m.annotator) (*m.annotator)(m.plan.model, batch, out.annotations, default_threads());
}

}  // namespace portalsim::speed
