// What a body costs: a page of per-scenario bodies' images (scene/bodies.h, use_page_bodies;
// assets/assets.h, with_subjects), and whole runs of the catalogue's subjects, a pool of
// random bodies and a body per scenario. Items are bodies and scenarios.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "cli/common.h"
#include "fixture.h"
#include "scene/bodies.h"
#include "schedule/pipeline.h"

namespace portalsim {
namespace {

// One page of bodies drawn and their three views' base images made (on every core), as a
// run of per-scenario bodies does on reaching a page; cpu_ms_per_body is every thread's.
void BM_BodyPageImages(benchmark::State& state) {
  const Catalogue base = default_catalogue();
  const AssetSet assets = build_assets(base, false);
  Catalogue page = base;
  uint64_t p = 0;
  const double cpu0 = bench::process_cpu_ms();
  for (auto _ : state) {
    use_page_bodies(page, 1, p++);
    const AssetSet drawn = with_subjects(assets, page);
    benchmark::DoNotOptimize(drawn.bases.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * kBodyPage));
  state.counters["cpu_ms_per_body"] = (bench::process_cpu_ms() - cpu0) / (state.iterations() * kBodyPage);
}
BENCHMARK(BM_BodyPageImages)->Unit(benchmark::kMillisecond)->UseRealTime();

// Arg: 0 the catalogue's subjects, 1 64 random bodies, 2 a body per scenario. 768 physics
// scenarios' images (four pages) to .npy, end to end.
void BM_BodiesRun(benchmark::State& state) {
  static cli::Session s = [] {
    cli::Session one;
    cli::open_catalogue(one, cli::CommonOptions{});
    cli::open_backend(one, cli::CommonOptions{});
    return one;
  }();
  RunSpec spec;
  spec.count = 768;
  spec.what = "images";
  spec.formats = {"npy"};
  spec.knobs["model"] = "physics";
  const char* bodies[] = {"catalogue", "random", "per-scenario"};
  spec.bodies = bodies[state.range(0)];
  cli::Session own;
  cli::open_catalogue(own, cli::CommonOptions{}, &spec, false);
  own.backend = s.backend->for_catalogue(own.catalogue, own.assets);
  state.SetLabel(spec.bodies);
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("portalsim-bench-" + std::to_string(::getpid()))).string();
  for (auto _ : state) {
    std::filesystem::remove_all(dir);
    const PipelineResult r = run_pipeline(spec, own.catalogue, own.assets, *own.backend, dir, PipelineOptions{});
    benchmark::DoNotOptimize(r.done);
  }
  std::filesystem::remove_all(dir);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * spec.count));
}
BENCHMARK(BM_BodiesRun)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace portalsim
