// The CPU reference backend: runs each camera view's chain of reference stages
// (backend/reference/stages.h) scenario by scenario, then pooling and metal.
#include <algorithm>

#include "backend/backend.h"
#include "backend/stages.h"

namespace portalsim {

namespace {

class ReferenceBackend final : public Backend {
 public:
  ReferenceBackend(const Catalogue& cat, const AssetSet& assets) : cat_(cat), assets_(assets) {
    for (const Sensor& s : cat.sensors) check_chain(s);
  }
  std::string name() const override { return "reference"; }
  std::unique_ptr<Backend> for_catalogue(const Catalogue& cat, const AssetSet& assets) const override {
    return std::make_unique<ReferenceBackend>(cat, assets);
  }
  std::vector<std::string> paths(const Plan& plan) const override {
    std::vector<std::string> taken;
    for (int k : rendered_views(plan)) taken.push_back(cat_.sensors[k].name + ": fp64 stages");
    if (plan.features) taken.push_back(std::string("features: ") + kPooledFeatures);
    return taken;
  }
  std::vector<int> rendered_views(const Plan& plan) const override {
    std::vector<int> views;
    for (size_t k = 0; k < cat_.sensors.size(); ++k)
      if (plan.renders(cat_.sensors[k], static_cast<int>(k))) views.push_back(static_cast<int>(k));
    return views;
  }

  void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) override {
    const size_t n = batch.size();
    prepare_output(out, cat_, plan, n);
    annotations(cat_, assets_, batch, plan, out);
    const int views = static_cast<int>(cat_.sensors.size());
    std::vector<std::vector<uint8_t>> images(views);
    reference::Field field;
    std::vector<ModelSettings> view_model;  // each view's knobs, its own camera's numbers over the run's
    for (const Sensor& sensor : cat_.sensors) view_model.push_back(plan.model.for_view(sensor));
    for (size_t i = 0; i < n; ++i) {
      const Scenario s = batch.at(i);
      const uint64_t index = batch.index_of(i);
      for (int k = 0; k < views; ++k) {
        const Sensor& sensor = cat_.sensors[k];
        if (!plan.renders(sensor, k)) continue;
        // Each scenario's own knobs where a knob is drawn (ModelSettings::at_scenario).
        const ModelSettings scenario_model = view_model[k].at_scenario(index);
        reference::ViewScene vs = reference::view_scene(cat_, assets_, scenario_model, k, s, index);
        vs.follow(plan);
        for (const std::string& stage : sensor.chain_for(plan.model.model)) view_stage(stage).reference(vs, field);
        images[k].assign(field.v.begin(), field.v.end());  // display left whole numbers 0..255
        if (plan.image(k))
          std::copy(images[k].begin(), images[k].end(), out.views[k].pixels.begin() + i * sensor.pixels());
      }
      if (plan.features) reference::pool(cat_, images, out.layout, &out.features[i * out.layout.image_features()]);
      if (plan.metal && plan.model.model == Model::physics)
        reference::metal_physics(cat_, assets_, plan.model.at_scenario(index), s, index, &out.metal[i * cat_.zones]);
      else if (plan.metal)
        reference::metal(cat_, plan.model.at_scenario(index), s, index, &out.metal[i * cat_.zones]);
    }
  }

 private:
  const Catalogue& cat_;
  const AssetSet& assets_;
};

}  // namespace

std::unique_ptr<Backend> make_reference_backend(const Catalogue& cat, const AssetSet& assets) {
  return std::make_unique<ReferenceBackend>(cat, assets);
}

}  // namespace portalsim
