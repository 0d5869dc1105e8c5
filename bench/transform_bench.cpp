// Randomised objects (--rotate, --scale, --flip): what affine sprite sampling costs the
// kernels, against the same batch placed as today.
//   ./build/portalsim_bench --benchmark_filter=Transform --benchmark_repetitions=3
// Args: batch size, threads (PoCL compute units: 1 or all). Counters: scenarios/s, and
// process_cpu_ms (every thread's CPU time per run, the steadier figure on a busy machine).
#include <benchmark/benchmark.h>

#include "fixture.h"

namespace portalsim {
namespace {
using bench::fx;

enum Mode { kToday, kBilinear, kFlip, kRotate, kAll, kAllFeatures, kTodayFeatures };

Plan plan_for(Mode mode) {
  Plan p;
  p.features = false;  // images: all three views
  switch (mode) {
    case kToday:
      break;
    case kBilinear:  // sub-pixel jitter, the per-pixel sampling path without transforms
      p.model.bilinear = true;
      p.model.jitter = 2;
      break;
    case kFlip:
      p.model.flip = true;
      break;
    case kRotate:
      p.model.rotate_lo = -180;
      p.model.rotate_hi = 180;
      break;
    case kAll:
    case kAllFeatures:
      p.model.rotate_lo = -30;
      p.model.rotate_hi = 30;
      p.model.scale_lo = 0.8;
      p.model.scale_hi = 1.25;
      p.model.flip = true;
      p.model.jitter = 2;
      break;
    case kTodayFeatures:
      break;
  }
  if (mode == kAllFeatures || mode == kTodayFeatures) {  // features only: dense with transforms, else sparse
    p.images = 0;
    p.features = true;
  }
  return p;
}

void BM_Transform(benchmark::State& state, Mode mode) {
  auto b = make_opencl_backend(fx().cat, fx().assets, state.range(1) == 1 ? fx().rt1 : fx().rt);
  bench::time_runs(state, *b, plan_for(mode), static_cast<size_t>(state.range(0)));
}

#define TRANSFORM_BENCH(name, mode) \
  BENCHMARK_CAPTURE(BM_Transform, name, mode)->Args({1024, 2})->Unit(benchmark::kMillisecond)->UseRealTime()
TRANSFORM_BENCH(images_today, kToday);
TRANSFORM_BENCH(images_bilinear_jitter, kBilinear);
TRANSFORM_BENCH(images_flip, kFlip);
TRANSFORM_BENCH(images_rotate, kRotate);
TRANSFORM_BENCH(images_rotate_scale_flip_jitter, kAll);
TRANSFORM_BENCH(features_today, kTodayFeatures);
TRANSFORM_BENCH(features_rotate_scale_flip_jitter, kAllFeatures);

}  // namespace
}  // namespace portalsim
