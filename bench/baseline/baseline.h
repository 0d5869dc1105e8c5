// The baselines of issue 14: plain C++ loops (OpenMP over scenarios, inner loops that
// g++ vectorises at -O3 -march=native) doing the kernels' work with output bit-identical
// to the standard tier. A kernel path slower than its baseline is a defect. They share
// no code with kernels/ or with the reference (host/backend/reference/).
#pragma once
#include "assets/assets.h"
#include "backend/backend.h"

namespace portalsim::baseline {

// Every camera view's images for `batch`, as the standard tier renders them: fp32,
// integer placement without jitter, pattern noise and per-pixel sensor noise
// (sigma = model.pixel_sigma) with the kernels' polynomial Box-Muller transform.
// `out` is sized as prepare_output does for a plan that keeps every view.
void render_images(const Catalogue& cat, const AssetSet& assets, const SceneBatch& batch, const ModelSettings& model,
                   BatchOutput& out);

}  // namespace portalsim::baseline
