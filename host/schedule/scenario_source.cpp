#include "schedule/scenario_source.h"

#include <algorithm>
#include <exception>
#include <mutex>

#include "base/error.h"
#include "base/parallel.h"
#include "base/spoken_list.h"
#include "plan/knobs.h"

namespace portalsim {

ScenarioSource::ScenarioSource(const RunSpec& spec, const Catalogue& cat)
    : model_(spec.settings().model), own_bodies_(spec.per_scenario_bodies()), regions_(cat.region_count()) {
  if (!spec.rule.empty()) rule_.emplace(cat, spec.rule, spec.where("rule"));
  if (!spec.scenarios.empty()) {
    list_ = std::make_shared<ScenarioListFile>(cat, spec.scenarios, false, drawn_number_keys());
    path_ = spec.scenarios;
    total_ = list_->size();
  } else {
    generator_.emplace(cat, generator_spec(spec, cat), spec.seed);
    total_ = spec.count;
  }
}

void ScenarioSource::fill(uint64_t at, size_t n, unsigned threads, SceneBatch& b) const {
  b.first_index = at;
  b.regions = regions_;
  b.subject.resize(n);
  b.objects.resize(n * regions_);
  b.label.resize(n);
  std::vector<Scenario> listed;
  std::vector<ListedTransforms> recorded;
  if (list_) {
    listed.resize(n);
    if (list_->has_transforms()) recorded.resize(n);
    list_->read(at, n, threads, listed.data(), recorded.empty() ? nullptr : recorded.data());
  }
  // Each part stops at its first bad row; the first of those is reported.
  std::mutex m;
  size_t bad_row = n;
  std::exception_ptr bad;
  parallel_for(n, n >= 1024 ? threads : 1, [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) {
      Scenario s;
      if (generator_) {
        s = (*generator_)(at + i);
      } else {
        s = listed[i];
        if (s.label < 0) s.label = rule_ && (*rule_)(s) ? 1 : 0;
        // Randomised objects are re-made from (seed, index, knobs), like every draw: a list
        // that records them must be re-made with the seed and knobs that drew them.
        if (!recorded.empty())
          for (int r = 0; r < regions_; ++r)
            if (s.objects[r] != kNoObject && object_transform(model_, at + i, r) != recorded[i].t[r]) {
              std::lock_guard<std::mutex> lock(m);
              if (i < bad_row)
                bad_row = i, bad = std::make_exception_ptr(InputError(
                                 path_ + ":" + std::to_string(recorded[i].line) + ": region" + std::to_string(r + 1) +
                                 ": its rotation, scale and flip are not what scenario " + std::to_string(at + i) +
                                 " of this run draws; re-make a list with the --seed, --rotate, --scale and --flip of "
                                 "the run that wrote it, from its first scenario"));
              return;
            }
      }
      b.subject[i] = static_cast<uint8_t>(own_bodies_ ? page_subject(at + i) : s.subject);
      std::copy(s.objects.begin(), s.objects.begin() + regions_, b.objects.begin() + i * regions_);
      b.label[i] = static_cast<uint8_t>(s.label);
    }
  });
  if (bad) std::rethrow_exception(bad);
}

void ScenarioSource::check(uint64_t begin, uint64_t end, unsigned threads) const {
  if (!list_) return;
  SceneBatch b(regions_);
  constexpr uint64_t kRows = 1u << 16;
  for (uint64_t at = begin; at < end; at += kRows) fill(at, static_cast<size_t>(std::min(kRows, end - at)), threads, b);
}

Plan run_plan(const RunSpec& spec, const Catalogue& cat) {
  Plan plan = spec.settings();
  plan.features = spec.wants_features();
  plan.metal = true;
  plan.images = spec.wants_images() ? kAllViews : 0;
  plan.annotations = spec.annotations;
  plan.own_subjects = spec.per_scenario_bodies();
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

void check_formats(const RunSpec& spec) {
  const std::vector<std::string> known = format_values();
  for (const std::string& f : spec.formats)
    if (std::find(known.begin(), known.end(), f) == known.end())
      throw InputError(spec.where("format") + ": \"" + f + "\" is not " + spoken_list(known, " or "));
}

SinkRequest sink_request(const RunSpec& spec, const Plan& plan, const ThreatRule* rule,
                         const nlohmann::json& identity) {
  SinkRequest r;
  r.formats = spec.formats;
  r.features = spec.wants_features();
  r.images = spec.wants_images();
  r.annotations = plan.annotations;
  r.image_tensors = spec.image_tensors();
  r.npy_image_tensors = spec.npy_image_tensors();
  r.compress = spec.compress;
  r.image_format = spec.image_format;
  r.rule = rule;
  r.identity = identity;
  return r;
}

}  // namespace portalsim
