// Every stage's output of one scenario, as the reference computes it: a look inside the
// sensor chains (`simulate --stages`), for checking a model or plotting a profile.
#pragma once
#include <cstdint>
#include <string>

#include "assets/assets.h"
#include "plan/plan.h"
#include "scene/scene.h"

namespace portalsim {

// Writes dir/<view>.<k>.<stage>.npy, float64 of the field's height x width, for each
// camera view and each stage k of its chain under plan's model (gray levels or kelvin,
// the raw grid after sampling). `dir` exists. Throws OutputError.
void write_stage_fields(const std::string& dir, const Catalogue& cat, const AssetSet& assets, const Plan& plan,
                        const Scenario& scene, uint64_t index);

}  // namespace portalsim
