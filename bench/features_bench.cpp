// The thesis's features-only path (as BM_FeaturesVsBaseline: block 10, pattern noise, no
// metal, batch 16384) timed by the CPU time of the whole process (every thread) beside
// the wall clock, and the loop of bench/baseline/ after it, alike. On a shared machine
// the wall clock counts the time other processes hold the cores; CPU time counts only
// this process's work, so 2 x scenarios per CPU second is the rate the 2 cores would give
// it alone (when both stay busy). Counters: kernel_per_s, baseline_per_s (wall),
// kernel_per_2cpu_s, baseline_per_2cpu_s (CPU time), kernel_vs_baseline_cpu (> 1: the
// kernels do the work in less CPU time).
//   ./build/portalsim_bench --benchmark_filter=FeaturesCpuTime --benchmark_repetitions=3
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>

#include "baseline.h"
#include "fixture.h"

namespace portalsim {
namespace {
using bench::fx;
using bench::make_batch;
using Clock = std::chrono::steady_clock;

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
double seconds(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void BM_FeaturesCpuTime(benchmark::State& state) {
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
  double wall_kernel = 0, wall_loop = 0, cpu_kernel = 0, cpu_loop = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const double c0 = process_cpu_seconds();
    cl->run(batch, plan, kernel);
    cpu_kernel += process_cpu_seconds() - c0;
    const double k = seconds(t0);
    state.SetIterationTime(k);
    wall_kernel += k;
    benchmark::DoNotOptimize(kernel.features.data());
  }
  // The loop as many times after the kernels, not between them: OpenMP's threads spin a
  // while after a parallel region, which would count in the kernels' CPU time.
  for (int64_t i = 0; i < state.iterations(); ++i) {
    const auto t0 = Clock::now();
    const double c0 = process_cpu_seconds();
    features.run(batch, loop);
    cpu_loop += process_cpu_seconds() - c0;
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
