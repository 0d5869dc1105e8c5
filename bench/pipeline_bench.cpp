// The scheduler end to end: generate -> backend -> sinks into a temporary folder, and
// the scenario generator alone. Items are scenarios.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "cli/common.h"
#include "scene/generator.h"
#include "schedule/pipeline.h"

namespace portalsim {
namespace {

cli::Session& session() {
  static cli::Session s = [] {
    cli::CommonOptions o;
    return cli::open_session(o);
  }();
  return s;
}

// Args: scenarios, format (0 npy, 1 csv, 2 arff).
void BM_Pipeline_features(benchmark::State& state) {
  RunSpec spec;
  spec.count = static_cast<uint64_t>(state.range(0));
  spec.rule = "gun";
  const char* formats[] = {"npy", "csv", "arff"};
  spec.formats = {formats[state.range(1)]};
  state.SetLabel(spec.formats[0]);
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("portalsim-bench-" + std::to_string(::getpid()))).string();
  for (auto _ : state) {
    std::filesystem::remove_all(dir);
    PipelineOptions opt;
    const PipelineResult r = run_pipeline(spec, session().catalogue, session().assets, *session().backend, dir, opt);
    benchmark::DoNotOptimize(r.done);
  }
  std::filesystem::remove_all(dir);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * spec.count));
}
BENCHMARK(BM_Pipeline_features)
    ->Args({200000, 0})
    ->Args({50000, 1})
    ->Args({50000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Generator(benchmark::State& state) {
  GeneratorSpec gs;
  gs.rule = "gun";
  gs.balance = state.range(0) != 0;
  Generator gen(session().catalogue, gs, 1);
  uint64_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(gen(i++));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
  state.SetLabel(gs.balance ? "balanced" : "plain");
}
BENCHMARK(BM_Generator)->Arg(0)->Arg(1);

}  // namespace
}  // namespace portalsim
