// The physics model against the thesis model, per scenario, in the same run:
//   ./build/portalsim_bench --benchmark_filter=Model --benchmark_repetitions=3
// Args: batch size, model (0 thesis, 1 physics), NETD in kelvin (physics only), tier (0
// standard, 1 fast: physics features-only from the raw grid; physics images with the fast
// tier's draws and display).
// The MMW camera's own processing (frames, window, display filter, smoothing), MMW images:
//   ./build/portalsim_bench --benchmark_filter=MmwCamera --benchmark_repetitions=3
// The MMW raw grid drawn per scenario from a list against one grid (each grid's scenarios a
// part of the batch of their own):
//   ./build/portalsim_bench --benchmark_filter=RawGrid --benchmark_repetitions=5
// The IR camera alone, and its physics chain cut after each stage:
//   ./build/portalsim_bench --benchmark_filter='Ir' --benchmark_repetitions=3
#include <benchmark/benchmark.h>

#include "backend/stages.h"
#include "fixture.h"
#include "plan/knobs.h"

namespace portalsim {
namespace {
using bench::fx;

Plan model_plan(const benchmark::State& state, bool images) {
  Plan p;
  p.model.model = state.range(1) == 1 ? Model::physics : Model::thesis;
  p.model.netd = static_cast<double>(state.range(2));
  if (state.range(3) == 1) p.fidelity = tier_fidelity(Tier::fast);
  if (images)
    p.features = false;
  else
    p.images = 0;
  return p;
}

void run_model(benchmark::State& state, Backend& backend, bool images) {
  const size_t n = static_cast<size_t>(state.range(0));
  const Plan plan = model_plan(state, images);
  // The features path as --timing names it: the raw-grid path where its gate applies.
  std::string label = std::string(model_name(plan.model.model)) + (images ? " images" : " features");
  for (const std::string& p : backend.paths(plan))
    if (p.rfind("features: physics_raw_features", 0) == 0) label += " (raw grid)";
  state.SetLabel(label);
  bench::time_runs(state, backend, plan, n);
}

void BM_ModelOpenCL(benchmark::State& state, bool images) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  run_model(state, *b, images);
}
void BM_ModelReference(benchmark::State& state, bool images) {
  auto b = make_reference_backend(fx().cat, fx().assets);
  run_model(state, *b, images);
}

BENCHMARK_CAPTURE(BM_ModelOpenCL, images, true)
    ->Args({1024, 0, 0, 0})
    ->Args({1024, 1, 0, 0})
    ->Args({1024, 1, 3, 0})
    ->Args({1024, 1, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ModelOpenCL, features, false)
    ->Args({4096, 0, 0, 0})
    ->Args({4096, 1, 3, 0})
    ->Args({4096, 1, 0, 1})
    ->Args({4096, 1, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ModelReference, images, true)
    ->Args({16, 0, 0, 0})
    ->Args({16, 1, 3, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The two MMW views' images under --model physics at NETD 3 K. Args: frames, automatic
// window (0 fixed, 1 auto), filter (0 bilinear, 1 bicubic), smoothing sigma in tenths of a
// view pixel, tier (0 standard, 1 fast: frames as one draw of NETD / sqrt(frames)).
void BM_MmwCamera(benchmark::State& state) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan p;
  if (state.range(4) == 1) p.fidelity = tier_fidelity(Tier::fast);
  p.model.model = Model::physics;
  p.model.frames = static_cast<int>(state.range(0));
  p.model.window_auto = state.range(1) == 1;
  p.model.display_filter = state.range(2) == 1 ? DisplayFilter::bicubic : DisplayFilter::bilinear;
  p.model.smooth = static_cast<double>(state.range(3)) / 10.0;
  p.images = (1u << fx().cat.sensor_index("upper")) | (1u << fx().cat.sensor_index("lower"));
  p.features = false;
  p.metal = false;
  state.SetLabel("physics MMW images");
  bench::time_runs(state, *b, p, 1024);
}
BENCHMARK(BM_MmwCamera)
    ->Args({1, 0, 0, 0, 0})
    ->Args({10, 0, 0, 0, 0})
    ->Args({10, 0, 0, 0, 1})
    ->Args({1, 1, 0, 0, 0})
    ->Args({1, 0, 1, 0, 0})
    ->Args({1, 0, 0, 20, 0})
    ->Args({10, 1, 1, 10, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The physics model's images of every view at the standard tier, or features only at the
// fast tier.
Plan images_or_features(bool images) {
  Plan p;
  p.model.model = Model::physics;
  if (images) {
    p.features = false;
  } else {
    p.fidelity = tier_fidelity(Tier::fast);
    p.images = 0;
  }
  return p;
}

// Args: what (0 images of every view, standard tier; 1 features only, fast tier), raw grid
// (0: 14x14, 1: 28x28, 2: 40x40, 3: drawn from 14x14,28x28,40x40).
void BM_RawGrid(benchmark::State& state) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  const bool images = state.range(0) == 0;
  Plan p = images_or_features(images);
  const char* grids[] = {"14x14", "28x28", "40x40", "14x14,28x28,40x40"};
  set_knob(p, *find_knob("mmw_raw"), grids[state.range(1)], "--mmw-raw");
  state.SetLabel(std::string(images ? "physics images, " : "physics features, fast, ") + grids[state.range(1)]);
  bench::time_runs(state, *b, p, images ? 1024 : 8192);
}
BENCHMARK(BM_RawGrid)->ArgsProduct({{0, 1}, {0, 1, 2, 3}})->Unit(benchmark::kMillisecond)->UseRealTime();

// Drawn outfits without and with folds. Args: what (0 images of every view, standard tier;
// 1 features only, fast tier), folds (0 none, 1 drawn from 0..1).
void BM_ClothingFolds(benchmark::State& state) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  const bool images = state.range(0) == 0;
  Plan p = images_or_features(images);
  set_knob(p, *find_knob("clothing"), "random", "--clothing");
  if (state.range(1) == 1) set_knob(p, *find_knob("clothing_folds"), "0..1", "--clothing-folds");
  state.SetLabel(std::string(images ? "physics images, " : "physics features, fast, ") +
                 (state.range(1) == 1 ? "outfits with folds" : "outfits"));
  bench::time_runs(state, *b, p, images ? 1024 : 8192);
}
BENCHMARK(BM_ClothingFolds)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

// The IR view's images only. Args: model (0 thesis, 1 physics), IR NETD in mK (physics).
void BM_IrImages(benchmark::State& state) {
  auto b = make_opencl_backend(fx().cat, fx().assets, fx().rt);
  Plan p;
  p.model.model = state.range(0) == 1 ? Model::physics : Model::thesis;
  p.model.ir_netd = static_cast<double>(state.range(1)) / 1000.0;
  p.images = 1u << fx().cat.sensor_index("ir");
  p.features = false;
  p.metal = false;
  state.SetLabel(std::string(model_name(p.model.model)) + " IR images");
  bench::time_runs(state, *b, p, 1024);
}

// The IR physics chain's first `range(0)` stages, then ir_display: a stage's cost is the
// difference from the prefix before it, but from ir_surface on the prefix takes the fast
// path (contact_shadow, heat_spread and ir_surface in ir_surface_fused).
void BM_IrPhysicsStages(benchmark::State& state) {
  Catalogue cat = fx().cat;
  std::vector<std::string>& chain = cat.sensors[cat.sensor_index("ir")].physics_chain;
  chain.resize(static_cast<size_t>(state.range(0)));
  chain.push_back("ir_display");
  auto b = make_opencl_backend(cat, fx().assets, fx().rt);
  Plan p;
  p.model.model = Model::physics;
  p.images = 1u << cat.sensor_index("ir");
  p.features = false;
  p.metal = false;
  state.SetLabel(chain[chain.size() - 2]);
  bench::time_runs(state, *b, p, 1024);
}

BENCHMARK(BM_IrImages)->Args({0, 0})->Args({1, 0})->Args({1, 50})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_IrPhysicsStages)->DenseRange(1, 4)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace portalsim
