// What every benchmark shares: the default catalogue, its assets, OpenCL runtimes on all
// compute units and on one, and generated scenario batches.
#pragma once
#include <benchmark/benchmark.h>

#include <memory>

#include "assets/assets.h"
#include "backend/backend.h"
#include "backend/opencl/opencl_backend.h"
#include "scene/generator.h"

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

// n scenarios of the generator (seed 1), 0 to max_objects objects each.
inline SceneBatch make_batch(size_t n, int max_objects = 4) {
  GeneratorSpec spec;
  spec.max_objects = max_objects;
  Generator gen(fx().cat, spec, 1);
  SceneBatch b;
  for (size_t i = 0; i < n; ++i) b.push(gen(i));
  return b;
}

// Times `backend` on n generated scenarios of `plan`, after one untimed run (tables,
// work-group compilation); items are scenarios.
inline void time_runs(benchmark::State& state, Backend& backend, const Plan& plan, size_t n) {
  const SceneBatch batch = make_batch(n);
  BatchOutput out;
  backend.run(batch, plan, out);
  for (auto _ : state) {
    backend.run(batch, plan, out);
    benchmark::DoNotOptimize(out.views.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

}  // namespace portalsim::bench
