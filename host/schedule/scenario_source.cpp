#include "schedule/scenario_source.h"

#include "base/error.h"
#include "base/parallel.h"

namespace portalsim {

ScenarioSource::ScenarioSource(const RunSpec& spec, const Catalogue& cat) {
  if (!spec.rule.empty()) rule_.emplace(cat, spec.rule, spec.where("rule"));
  if (!spec.scenarios.empty()) {
    std::vector<ListedTransforms> recorded;
    listed_ = read_scenario_file(cat, spec.scenarios, &recorded);
    total_ = listed_.size();
    // Randomised objects are re-made from (seed, index, knobs), like every draw: a list
    // that records them must be re-made with the seed and knobs that drew them.
    const ModelSettings model = spec.settings().model;
    for (size_t i = 0; i < recorded.size(); ++i)
      for (int r = 0; r < kRegions; ++r)
        if (listed_[i].objects[r] != kNoObject && object_transform(model, i, r) != recorded[i].t[r])
          throw InputError(recorded[i].where + ": region" + std::to_string(r + 1) +
                           ": its rotation, scale and flip are not what scenario " + std::to_string(i) +
                           " of this run draws; re-make a list with the --seed, --rotate, --scale and --flip of "
                           "the run that wrote it, from its first scenario");
  } else {
    generator_.emplace(cat, generator_spec(spec, cat), spec.seed);
    total_ = spec.count;
  }
}

Scenario ScenarioSource::operator()(uint64_t i) const {
  if (generator_) return (*generator_)(i);
  Scenario s = listed_[i];
  if (s.label < 0) s.label = rule_ && (*rule_)(s) ? 1 : 0;
  return s;
}

void ScenarioSource::fill(uint64_t at, size_t n, unsigned threads, SceneBatch& b) const {
  b.first_index = at;
  b.subject.resize(n);
  b.objects.resize(n * kRegions);
  b.label.resize(n);
  parallel_for(n, n >= 1024 ? threads : 1, [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) {
      const Scenario s = (*this)(at + i);
      b.subject[i] = static_cast<uint8_t>(s.subject);
      std::copy(s.objects.begin(), s.objects.end(), b.objects.begin() + i * kRegions);
      b.label[i] = static_cast<uint8_t>(s.label);
    }
  });
}

Plan run_plan(const RunSpec& spec, const Catalogue& cat) {
  Plan plan = spec.settings();
  plan.features = spec.wants_features();
  plan.metal = true;
  plan.images = spec.wants_images() ? kAllViews : 0;
  plan.annotations = spec.annotations;
  validate(plan, cat);
  return plan;
}

SinkContext plan_sink_context(const Plan& plan, const Catalogue& cat, const AssetSet& assets, unsigned threads,
                              const std::string& image_format) {
  SinkContext ctx;
  ctx.cat = &cat;
  ctx.assets = &assets;
  ctx.layout = FeatureLayout::of(cat, plan.model.block);
  ctx.threads = threads;
  ctx.model = plan.model;
  ctx.image_format = image_format;
  ctx.palette = procedural::ir_palette(plan.palette);
  return ctx;
}

TensorOptions h5_tensor_options(const RunSpec& spec, const Plan& plan, const ThreatRule* rule) {
  TensorOptions topt;
  topt.rule = rule;
  topt.annotations = plan.annotations;
  topt.h5 = true;
  topt.compress = spec.compress;
  topt.images = spec.wants_images();
  topt.features = spec.wants_features();
  return topt;
}

}  // namespace portalsim
