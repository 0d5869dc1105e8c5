// Kernel paths against their baselines (bench/baseline/), timed in the same benchmark,
// one after the other each iteration, on the same scenarios. Counters: kernel_per_s and
// baseline_per_s (scenarios/s), and kernel_vs_baseline (> 1: the kernels are faster).
//   ./build/portalsim_bench --benchmark_filter=VsBaseline --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <chrono>

#include "baseline.h"
#include "fixture.h"

namespace portalsim {
namespace {
using bench::fx;
using bench::make_batch;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Arg: per-pixel noise sigma (0 = images, 2 = noisy images, as in issue 14's table).
void BM_ImagesVsBaseline(benchmark::State& state) {
  auto cl = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan plan;
  plan.features = false;
  plan.metal = false;
  plan.model.pixel_sigma = static_cast<double>(state.range(0));
  const size_t n = 1024;
  const SceneBatch batch = make_batch(n);
  BatchOutput kernel, loop;
  cl->run(batch, plan, kernel);
  prepare_output(loop, fx().cat, plan, n);
  baseline::render_images(fx().cat, fx().assets, batch, plan.model, loop);
  double t_kernel = 0, t_loop = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    cl->run(batch, plan, kernel);
    const double k = seconds(t0);
    t0 = Clock::now();
    baseline::render_images(fx().cat, fx().assets, batch, plan.model, loop);
    const double b = seconds(t0);
    state.SetIterationTime(k);
    t_kernel += k;
    t_loop += b;
    benchmark::DoNotOptimize(loop.views.data());
  }
  const double scenarios = static_cast<double>(state.iterations() * n);
  state.counters["kernel_per_s"] = scenarios / t_kernel;
  state.counters["baseline_per_s"] = scenarios / t_loop;
  state.counters["kernel_vs_baseline"] = t_loop / t_kernel;
  state.SetItemsProcessed(static_cast<int64_t>(scenarios));
  state.SetLabel(state.range(0) ? "noisy images" : "images");
}
BENCHMARK(BM_ImagesVsBaseline)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseManualTime();

// The thesis's features-only path (block 10, pattern noise, no metal): the sparse kernels
// against the same algorithm as loops, tables made before timing in both.
void BM_FeaturesVsBaseline(benchmark::State& state) {
  auto cl = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan plan;
  plan.images = 0;
  plan.metal = false;
  const size_t n = 16384;
  const SceneBatch batch = make_batch(n);
  BatchOutput kernel, loop;
  cl->run(batch, plan, kernel);
  prepare_output(loop, fx().cat, plan, n);
  const baseline::SparseFeatures features(fx().cat, fx().assets, plan.model);
  features.run(batch, loop);
  double t_kernel = 0, t_loop = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    cl->run(batch, plan, kernel);
    const double k = seconds(t0);
    t0 = Clock::now();
    features.run(batch, loop);
    const double b = seconds(t0);
    state.SetIterationTime(k);
    t_kernel += k;
    t_loop += b;
    benchmark::DoNotOptimize(loop.features.data());
  }
  const double scenarios = static_cast<double>(state.iterations() * n);
  state.counters["kernel_per_s"] = scenarios / t_kernel;
  state.counters["baseline_per_s"] = scenarios / t_loop;
  state.counters["kernel_vs_baseline"] = t_loop / t_kernel;
  state.SetItemsProcessed(static_cast<int64_t>(scenarios));
}
BENCHMARK(BM_FeaturesVsBaseline)->Unit(benchmark::kMillisecond)->UseManualTime();

}  // namespace
}  // namespace portalsim
