// Camera-view stages, one by one: the chain of stage kernels cut after each stage (then
// display), and
// the same chain of reference stages, with per-pixel noise on so that every stage works.
// A stage's cost is the difference between its prefix and the one before it. Also the
// fused render_view (the declared fast path) against the full chain of stage kernels.
//   ./build/portalsim_bench --benchmark_filter='Stage|Chain'
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include "backend/annotate.h"
#include "backend/stages.h"
#include "fixture.h"

namespace portalsim {
namespace {
using bench::fx;
using bench::make_batch;

// The default catalogue with every view's chain cut to its first `stages` stages, then
// display (which every chain ends with).
struct Prefix {
  Catalogue cat;
  explicit Prefix(size_t stages) : cat(fx().cat) {
    for (Sensor& s : cat.sensors) {
      s.chain.resize(std::min(stages, s.chain.size() - 1));
      s.chain.push_back("display");
    }
  }
};

Plan images_plan() {
  Plan p;
  p.features = false;
  p.metal = false;
  p.model.pixel_sigma = 2;
  p.fidelity.fused = false;
  return p;
}

void time_backend(benchmark::State& state, Backend& backend, const Plan& plan, size_t n) {
  bench::time_runs(state, backend, plan, n);
  state.SetLabel(fx().cat.sensors[0].chain[state.range(0) - 1]);
}

// Arg: the stages kept before display (1 = composite only ... 3 = the whole chain).
void BM_StageOpenCL(benchmark::State& state) {
  Prefix p(static_cast<size_t>(state.range(0)));
  auto b = make_opencl_backend(p.cat, fx().assets, fx().rt);
  time_backend(state, *b, images_plan(), 1024);
}
void BM_StageReference(benchmark::State& state) {
  Prefix p(static_cast<size_t>(state.range(0)));
  auto b = make_reference_backend(p.cat, fx().assets);
  time_backend(state, *b, images_plan(), 32);
}
// Arg: 1 fused render_view, 0 the chain of stage kernels.
void BM_ChainFusedOrStaged(benchmark::State& state) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan plan = images_plan();
  plan.fidelity.fused = state.range(0) == 1;
  bench::time_runs(state, *b, plan, 1024);
  state.SetLabel(plan.fidelity.fused ? "fused render_view" : "stage kernels");
}

// An images run's batch on the kernels (default model, every view kept), with boxes and
// instance masks (Arg 1) or without (Arg 0): the difference is what annotations cost.
void BM_ImagesAnnotations(benchmark::State& state) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan plan;
  plan.features = false;
  plan.annotations = state.range(0) == 1;
  const size_t n = 1024;
  const SceneBatch batch = make_batch(n);
  BatchOutput out;
  b->run(batch, plan, out);
  const double cpu0 = bench::process_cpu_ms();
  for (auto _ : state) {
    b->run(batch, plan, out);
    benchmark::DoNotOptimize(out.views.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
  state.SetLabel(plan.annotations ? "images + annotations" : "images");
  // Every thread's CPU time (PoCL's and the host's), steadier than wall time on a busy machine.
  state.counters["process_cpu_ms"] =
      benchmark::Counter(bench::process_cpu_ms() - cpu0, benchmark::Counter::kAvgIterations);
}

// annotate() alone on one host thread, default model, batches of 1,024: the same batch
// each time as above (Arg 0), or two batches in turn as in a run (Arg 1; the last batch's
// objects are cleared elsewhere than the new ones are painted).
void BM_Annotate(benchmark::State& state) {
  const size_t n = 1024;
  GeneratorSpec spec;
  Generator gen(fx().cat, spec, 1);
  const int R = fx().cat.region_count();
  SceneBatch batches[2] = {SceneBatch(R), SceneBatch(R)};
  for (size_t i = 0; i < 2 * n; ++i) batches[i / n].push(gen(i));
  batches[1].first_index = n;
  std::vector<ViewAnnotations> out;
  Annotator annotate(fx().cat, fx().assets);  // as a backend keeps one
  annotate(ModelSettings{}, batches[0], out);
  size_t turn = 0;
  for (auto _ : state) {
    annotate(ModelSettings{}, batches[state.range(0) ? ++turn % 2 : 0], out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

BENCHMARK(BM_StageOpenCL)->DenseRange(1, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StageReference)->DenseRange(1, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ChainFusedOrStaged)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ImagesAnnotations)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Annotate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace portalsim
