// What every benchmark shares: the default catalogue, its assets, OpenCL runtimes on all
// compute units and on one, and generated scenario batches.
#pragma once
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <memory>

#include "assets/assets.h"
#include "backend/backend.h"
#include "backend/opencl/opencl_backend.h"
#include "scene/generator.h"
#include "speed/paths.h"

namespace portalsim::bench {

struct Fixture {
  Catalogue cat = default_catalogue();
  AssetSet assets = build_assets(cat);
  std::shared_ptr<OpenCLRuntime> rt = std::make_shared<OpenCLRuntime>();
  // One compute unit: PoCL runs the kernels on a single thread.
  std::shared_ptr<OpenCLRuntime> rt1 = std::make_shared<OpenCLRuntime>(OpenCLOptions{"", "", 1});
};
inline Fixture& fx() {
  static Fixture f;
  return f;
}

// n scenarios of the generator (seed 1), 0 to max_objects objects each, as portalsim bench makes them.
inline SceneBatch make_batch(size_t n, int max_objects = 4) { return speed::make_batch(fx().cat, n, max_objects); }

// Every thread's CPU time so far (PoCL's and the host's), in ms: steadier than wall time
// on a busy machine.
inline double process_cpu_ms() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

// Times `backend` on n generated scenarios of `plan`, after one untimed run (tables,
// work-group compilation); items are scenarios, and process_cpu_ms is the CPU time of
// every thread per run.
inline void time_runs(benchmark::State& state, Backend& backend, const Plan& plan, size_t n) {
  const SceneBatch batch = make_batch(n);
  BatchOutput out;
  backend.run(batch, plan, out);
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    backend.run(batch, plan, out);
    benchmark::DoNotOptimize(out.views.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
  state.counters["process_cpu_ms"] = benchmark::Counter(process_cpu_ms() - cpu0, benchmark::Counter::kAvgIterations);
}

}  // namespace portalsim::bench
