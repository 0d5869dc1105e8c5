// The batch pipeline: generate -> plan -> backend -> sinks, for any number of
// scenarios in bounded memory. The main thread generates and computes batch k while a
// writer thread writes batch k-1 (double buffering); after each batch the writer
// records a checkpoint, so an interrupted run resumes byte-identically.
#pragma once
#include <atomic>
#include <string>

#include "assets/assets.h"
#include "backend/backend.h"
#include "scene/catalogue.h"
#include "schedule/run_spec.h"

namespace portalsim {

struct PipelineOptions {
  size_t batch = 0;      // 0 = sized from the outputs (about 16 MiB per batch)
  unsigned threads = 0;  // host threads for generating and writing; 0 = all cores
  uint64_t shard = 0, shards = 1;
  bool resume = false;
  bool progress = false;                    // draw a progress bar on stderr
  const std::atomic<bool>* stop = nullptr;  // set by a signal: finish the batch, checkpoint, stop
};

struct PipelineResult {
  uint64_t begin = 0, end = 0;  // the index range this run covers
  uint64_t done = 0;            // scenarios written by this invocation
  uint64_t positive = 0, negative = 0;
  double seconds = 0, compute_seconds = 0, write_wait_seconds = 0;
  size_t batch = 0;
  bool already_complete = false, interrupted = false;
};

PipelineResult run_pipeline(const RunSpec& spec, const Catalogue& cat, const AssetSet& assets, Backend& backend,
                            const std::string& dir, const PipelineOptions& options);

// Whether `dir` holds the finished run of `spec`'s whole range, as run_pipeline and
// run_ranked both make it. Throws when it does without `resume`, or when that run's
// parameters differ (naming every key that does).
bool holds_finished_run(const RunSpec& spec, const Catalogue& cat, const std::string& dir, bool resume);

// Scenarios per batch for a plan on `backend`: about 16 MiB of outputs and rendered views
// (those its paths render), between 64 and 16384.
size_t default_batch(const Plan& plan, const Catalogue& cat, const Backend& backend);

}  // namespace portalsim
