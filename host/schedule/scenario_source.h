// What generate makes of a spec, a batch at a time: its scenarios, its plan and data.h5's
// rows. The pipeline writes them to files; Python (python/) hands the same rows over as
// NumPy arrays, so both give the same bytes for scenario i.
#pragma once
#include <optional>
#include <vector>

#include "backend/backend.h"
#include "schedule/run_spec.h"
#include "sink/sinks.h"
#include "sink/tensors.h"

namespace portalsim {

// Where scenarios come from: the generator, or a listed file (a listed scenario without a
// label takes the rule's). The rule also gives data.h5 its region labels.
class ScenarioSource {
 public:
  ScenarioSource(const RunSpec& spec, const Catalogue& cat);
  uint64_t total() const { return total_; }
  bool listed() const { return !generator_; }
  const ThreatRule* rule() const { return rule_ ? &*rule_ : nullptr; }
  Scenario operator()(uint64_t i) const;
  // Scenarios [at, at + n) into `b` (on `threads` threads).
  void fill(uint64_t at, size_t n, unsigned threads, SceneBatch& b) const;

 private:
  std::optional<Generator> generator_;
  std::vector<Scenario> listed_;
  std::optional<ThreatRule> rule_;
  uint64_t total_ = 0;
};

// The plan generate runs for `spec`: its model and fidelity, metal, and the features and
// images it asks for; checked against the catalogue.
Plan run_plan(const RunSpec& spec, const Catalogue& cat);

// The sinks' context for `plan` (no folder: the caller sets dir, rows and done).
SinkContext plan_sink_context(const Plan& plan, const Catalogue& cat, const AssetSet& assets, unsigned threads,
                              const std::string& image_format);

// data.h5's tensors for `spec` (generate --format h5).
TensorOptions h5_tensor_options(const RunSpec& spec, const Plan& plan, const ThreatRule* rule);

}  // namespace portalsim
