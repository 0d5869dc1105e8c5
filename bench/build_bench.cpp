// Kernel build time, kept out of every other benchmark: a cold build (options no cached
// program has, so PoCL compiles from source) and a warm one (the same options again,
// served from PoCL's cache in ~/.cache/pocl or $POCL_CACHE_DIR).
#include <benchmark/benchmark.h>

#include <chrono>
#include <random>

#include "backend/opencl/kernels.h"
#include "scene/catalogue.h"

namespace portalsim {
namespace {

void BM_KernelBuild(benchmark::State& state) {
  const bool cold = state.range(0) == 0;
  static OpenCLRuntime rt;
  std::random_device rd;
  // The standard tier's options for the built-in catalogue, as its backend builds them.
  const std::string counts =
      std::string(" ").append(opencl::build_options(Fidelity{}, opencl::KernelCounts::of(default_catalogue())));
  const std::string warm_options = "-DPORTALSIM_BENCH_WARM=1" + counts;
  cl::Program(rt.context(), OpenCLRuntime::source()).build(warm_options.c_str());  // fill the cache once
  for (auto _ : state) {
    // A fresh define changes the cache key: PoCL must compile.
    const std::string options =
        cold ? "-DPORTALSIM_BENCH_NONCE=" + std::to_string(rd()) + std::to_string(rd()) + counts : warm_options;
    cl::Program p(rt.context(), OpenCLRuntime::source());
    p.build(options.c_str());
    cl::Kernel k(p, "render_view");  // kernels exist: the build really finished
    benchmark::DoNotOptimize(k());
  }
  state.SetLabel(cold ? "cold cache" : "warm cache");
}
BENCHMARK(BM_KernelBuild)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
}  // namespace portalsim
