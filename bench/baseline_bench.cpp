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

// Each iteration runs `kernel` (its time is the iteration's) then `loop` on n scenarios;
// the counters give both rates and their ratio.
template <class Kernel, class Loop>
void time_against_baseline(benchmark::State& state, size_t n, Kernel kernel, Loop loop) {
  double t_kernel = 0, t_loop = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    kernel();
    const double k = seconds(t0);
    t0 = Clock::now();
    loop();
    const double b = seconds(t0);
    state.SetIterationTime(k);
    t_kernel += k;
    t_loop += b;
  }
  const double scenarios = static_cast<double>(state.iterations() * n);
  state.counters["kernel_per_s"] = scenarios / t_kernel;
  state.counters["baseline_per_s"] = scenarios / t_loop;
  state.counters["kernel_vs_baseline"] = t_loop / t_kernel;
  state.SetItemsProcessed(static_cast<int64_t>(scenarios));
}

// Arg: per-pixel noise sigma (0 = images, 2 = noisy images, as in issue 14's table).
void BM_ImagesVsBaseline(benchmark::State& state) {
  auto cl = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  const Plan plan = speed::images_plan(static_cast<double>(state.range(0)));
  const size_t n = 1024;
  const SceneBatch batch = make_batch(n);
  BatchOutput kernel, loop;
  cl->run(batch, plan, kernel);
  prepare_output(loop, fx().cat, plan, n);
  baseline::render_images(fx().cat, fx().assets, batch, plan.model, loop);
  time_against_baseline(
      state, n, [&] { cl->run(batch, plan, kernel); },
      [&] {
        baseline::render_images(fx().cat, fx().assets, batch, plan.model, loop);
        benchmark::DoNotOptimize(loop.views.data());
      });
  state.SetLabel(state.range(0) ? "noisy images" : "images");
}
BENCHMARK(BM_ImagesVsBaseline)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseManualTime();

// The thesis's features-only path (block 10, pattern noise, no metal): the sparse kernels
// against the same algorithm as loops, tables made before timing in both.
// Both sides of the features-only comparison, each run once before timing.
struct FeaturesPair {
  static constexpr size_t n = 16384;
  std::unique_ptr<Backend> cl = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan plan = speed::features_plan();
  SceneBatch batch = make_batch(n);
  BatchOutput kernel, loop;
  baseline::SparseFeatures features{fx().cat, fx().assets, plan.model};
  FeaturesPair() {
    cl->run(batch, plan, kernel);
    prepare_output(loop, fx().cat, plan, n);
    features.run(batch, loop);
  }
};

void BM_FeaturesVsBaseline(benchmark::State& state) {
  FeaturesPair fp;
  auto& [cl, plan, batch, kernel, loop, features] = fp;
  const size_t n = FeaturesPair::n;
  time_against_baseline(
      state, n, [&] { cl->run(batch, plan, kernel); },
      [&] {
        features.run(batch, loop);
        benchmark::DoNotOptimize(loop.features.data());
      });
}
BENCHMARK(BM_FeaturesVsBaseline)->Unit(benchmark::kMillisecond)->UseManualTime();

// BM_FeaturesCpuTime: the thesis's features-only path (as BM_FeaturesVsBaseline: block 10, pattern noise, no
// metal, batch 16384) timed by the CPU time of the whole process (every thread) beside
// the wall clock, and the loop of bench/baseline/ after it, alike. On a shared machine
// the wall clock counts the time other processes hold the cores; CPU time counts only
// this process's work, so 2 x scenarios per CPU second is the rate the 2 cores would give
// it alone (when both stay busy). Counters: kernel_per_s, baseline_per_s (wall),
// kernel_per_2cpu_s, baseline_per_2cpu_s (CPU time), kernel_vs_baseline_cpu (> 1: the
// kernels do the work in less CPU time).
//   ./build/portalsim_bench --benchmark_filter=FeaturesCpuTime --benchmark_repetitions=3
void BM_FeaturesCpuTime(benchmark::State& state) {
  FeaturesPair fp;
  auto& [cl, plan, batch, kernel, loop, features] = fp;
  const size_t n = FeaturesPair::n;
  double wall_kernel = 0, wall_loop = 0, cpu_kernel = 0, cpu_loop = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const double c0 = bench::process_cpu_ms() * 1e-3;
    cl->run(batch, plan, kernel);
    cpu_kernel += bench::process_cpu_ms() * 1e-3 - c0;
    const double k = seconds(t0);
    state.SetIterationTime(k);
    wall_kernel += k;
    benchmark::DoNotOptimize(kernel.features.data());
  }
  // The loop as many times after the kernels, not between them: OpenMP's threads spin a
  // while after a parallel region, which would count in the kernels' CPU time.
  for (int64_t i = 0; i < state.iterations(); ++i) {
    const auto t0 = Clock::now();
    const double c0 = bench::process_cpu_ms() * 1e-3;
    features.run(batch, loop);
    cpu_loop += bench::process_cpu_ms() * 1e-3 - c0;
    wall_loop += seconds(t0);
    benchmark::DoNotOptimize(loop.features.data());
  }
  const double scenarios = static_cast<double>(state.iterations() * n);
  state.counters["kernel_per_s"] = scenarios / wall_kernel;
  state.counters["baseline_per_s"] = scenarios / wall_loop;
  state.counters["kernel_per_2cpu_s"] = 2 * scenarios / cpu_kernel;
  state.counters["baseline_per_2cpu_s"] = 2 * scenarios / cpu_loop;
  state.counters["kernel_vs_baseline_cpu"] = cpu_loop / cpu_kernel;
  state.SetItemsProcessed(static_cast<int64_t>(scenarios));
}
BENCHMARK(BM_FeaturesCpuTime)->Unit(benchmark::kMillisecond)->UseManualTime();

}  // namespace
}  // namespace portalsim
