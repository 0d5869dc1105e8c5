// Kernels and fused paths against the CPU reference, per scenario.
//   ./build/portalsim_bench --benchmark_filter=... --benchmark_repetitions=5
// Counters: scenarios/s ("items_per_second"). Kernel builds happen once, before timing.
#include <benchmark/benchmark.h>

#include "fixture.h"

namespace portalsim {
namespace {
using bench::fx;

enum Path { kFeaturesSparse, kFeaturesDense, kImages, kNoisyImages, kMetal, kMetalPhysics };

Plan plan_for(Path path, int block) {
  Plan p;
  p.model.block = block;
  switch (path) {
    case kFeaturesSparse:
      p.images = 0;
      break;
    case kFeaturesDense:
      p.images = 0;
      p.fidelity.pooling = Pooling::dense;
      break;
    case kImages:
      p.features = false;
      break;
    case kNoisyImages:  // per-pixel sensor noise, sigma 2 (issue 14's table)
      p.features = false;
      p.model.pixel_sigma = 2;
      break;
    case kMetal:
      p.images = 0;
      p.features = false;
      break;
    case kMetalPhysics:  // the coil model (docs/model/metal.md)
      p.images = 0;
      p.features = false;
      p.model.model = Model::physics;
      break;
  }
  return p;
}

void run(benchmark::State& state, Backend& backend, Path path, Tier tier = Tier::standard) {
  const size_t n = static_cast<size_t>(state.range(0));
  Plan plan = plan_for(path, static_cast<int>(state.range(1)));
  const Pooling pooling = plan.fidelity.pooling;
  plan.fidelity = tier_fidelity(tier);
  if (path == kFeaturesDense) plan.fidelity.pooling = pooling;
  bench::time_runs(state, backend, plan, n);
}

// Args: batch size, block size, threads (PoCL compute units: 1 or all).
void BM_OpenCL(benchmark::State& state, Path path) {
  auto b = make_opencl_backend(fx().cat, fx().assets, state.range(2) == 1 ? fx().rt1 : fx().rt);
  run(state, *b, path);
}
// Args: batch size, block size, tier (0 fast, 1 standard, 2 exact).
void BM_Tier(benchmark::State& state, Path path) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  const Tier t = state.range(2) == 0 ? Tier::fast : state.range(2) == 2 ? Tier::exact : Tier::standard;
  state.SetLabel(tier_name(t));
  run(state, *b, path, t);
}
void BM_Reference(benchmark::State& state, Path path) {
  auto b = make_reference_backend(fx().cat, fx().assets);
  run(state, *b, path);
}

BENCHMARK_CAPTURE(BM_OpenCL, features_sparse, kFeaturesSparse)
    ->ArgsProduct({{1, 64, 1024, 4096, 16384, 65536}, {10}, {2}})
    ->ArgsProduct({{16384}, {5, 20}, {2}})
    ->ArgsProduct({{16384}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_OpenCL, features_dense, kFeaturesDense)
    ->ArgsProduct({{1024}, {5, 10, 20}, {2}})
    ->ArgsProduct({{1024}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_OpenCL, images, kImages)
    ->ArgsProduct({{1, 256, 1024}, {10}, {2}})
    ->ArgsProduct({{1024}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_OpenCL, metal, kMetal)
    ->ArgsProduct({{65536}, {10}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_OpenCL, metal_physics, kMetalPhysics)
    ->ArgsProduct({{65536}, {10}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Tier, features, kFeaturesSparse)
    ->ArgsProduct({{16384}, {10}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Tier, images, kImages)
    ->ArgsProduct({{1024}, {10}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Tier, noisy_images, kNoisyImages)
    ->ArgsProduct({{1024}, {10}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Reference, features, kFeaturesDense)
    ->ArgsProduct({{64}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Reference, images, kImages)
    ->ArgsProduct({{64}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Reference, metal, kMetal)
    ->ArgsProduct({{65536}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Reference, metal_physics, kMetalPhysics)
    ->ArgsProduct({{4096}, {10}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace portalsim

BENCHMARK_MAIN();
