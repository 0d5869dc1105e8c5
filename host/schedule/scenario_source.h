// What generate makes of a spec, a batch at a time: its scenarios, its plan and data.h5's
// rows. The pipeline writes them to files; Python (python/) hands the same rows over as
// NumPy arrays, so both give the same bytes for scenario i.
#pragma once
#include <memory>
#include <optional>
#include <vector>

#include "backend/backend.h"
#include "scene/scenario_list.h"
#include "schedule/run_spec.h"
#include "sink/sink_kinds.h"
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
  // Scenarios [at, at + n) into `b` (on `threads` threads; its stride becomes the
  // catalogue's). A listed source reads them from its file, and a bad row throws InputError
  // naming its line.
  void fill(uint64_t at, size_t n, unsigned threads, SceneBatch& b) const;
  // Reads and checks scenarios [begin, end) of a list, keeping none (a generator has nothing
  // to check): a run checks its range before it writes anything, so a bad row far down a
  // long list leaves no output behind.
  void check(uint64_t begin, uint64_t end, unsigned threads) const;

 private:
  std::optional<Generator> generator_;
  std::shared_ptr<ScenarioListFile> list_;  // read as a stream: memory stays flat
  std::string path_;
  ModelSettings model_;  // the knobs a list's recorded transforms are checked against
  bool own_bodies_;      // per-scenario bodies: a scenario's subject is its place in its page
  int regions_ = 0;      // the catalogue's: the batches' stride
  std::optional<ThreatRule> rule_;
  uint64_t total_ = 0;
};

// The plan generate runs for `spec`: its model and fidelity, metal, and the features and
// images it asks for; checked against the catalogue.
Plan run_plan(const RunSpec& spec, const Catalogue& cat);

// The sinks' context for `plan` (no folder: the caller sets dir, rows and done).
SinkContext plan_sink_context(const Plan& plan, const Catalogue& cat, const AssetSet& assets, unsigned threads,
                              const std::string& image_format);

// Throws InputError naming the option where a --format value is none a sink kind answers.
void check_formats(const RunSpec& spec);

// What `spec` asks of its outputs, for the sinks (sink/sink_kinds.h).
SinkRequest sink_request(const RunSpec& spec, const Plan& plan, const ThreatRule* rule,
                         const nlohmann::json& identity = {});

}  // namespace portalsim
