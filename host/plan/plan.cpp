#include "plan/plan.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"

namespace portalsim {

FeatureLayout FeatureLayout::of(const Catalogue& cat, int block) {
  FeatureLayout f;
  f.block = block;
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& s = cat.sensors[k];
    if (!s.pooled) continue;
    f.pooled.push_back(static_cast<int>(k));
    f.view_names.push_back(s.name);
    f.blocks_x = (s.width + block - 1) / block;
    f.blocks_y = (s.height + block - 1) / block;
  }
  return f;
}

int FeatureLayout::block_for_grid(const Catalogue& cat, int w, int h) {
  int longest = 0;
  for (const Sensor& s : cat.sensors)
    if (s.pooled) longest = std::max({longest, s.width, s.height});
  for (int block = 1; block <= longest; ++block) {
    bool fits = true;
    for (const Sensor& s : cat.sensors)
      if (s.pooled && ((s.width + block - 1) / block != w || (s.height + block - 1) / block != h)) fits = false;
    if (fits && longest > 0) return block;
  }
  return 0;
}

std::vector<std::string> FeatureLayout::names() const {
  std::vector<std::string> n;
  for (const std::string& view : view_names)
    for (int by = 0; by < blocks_y; ++by)
      for (int bx = 0; bx < blocks_x; ++bx) n.push_back(view + "_r" + std::to_string(by) + "_c" + std::to_string(bx));
  for (int r = 1; r <= kRegions; ++r) n.push_back("region" + std::to_string(r));
  for (int z = 1; z <= kZones; ++z) n.push_back("zone" + std::to_string(z));
  return n;
}

Fidelity tier_fidelity(Tier t) {
  Fidelity f;
  switch (t) {
    case Tier::exact:
      f.precision = Precision::fp64;
      f.pooling = Pooling::dense;
      break;
    case Tier::standard:
      break;
    case Tier::fast:
      f.precision = Precision::fixed16;
      f.fast_math = true;
      f.noise = NoiseModel::block_mean;
      break;
  }
  return f;
}

Tier parse_tier(const std::string& name, const std::string& where) {
  if (name == "fast") return Tier::fast;
  if (name == "standard") return Tier::standard;
  if (name == "exact") return Tier::exact;
  throw InputError(where + ": \"" + name + "\" is not a tier (fast, standard, exact)");
}

void set_fidelity_knob(Fidelity& f, const std::string& knob, const std::string& value, const std::string& where) {
  const auto bad = [&](const char* allowed) {
    return InputError(where + ": \"" + value + "\" is not one of " + allowed);
  };
  if (knob == "precision") {
    if (value == "fp32")
      f.precision = Precision::fp32;
    else if (value == "fp64")
      f.precision = Precision::fp64;
    else if (value == "fixed16")
      f.precision = Precision::fixed16;
    else
      throw bad("fp32, fp64, fixed16");
  } else if (knob == "pooling") {
    if (value == "sparse")
      f.pooling = Pooling::sparse;
    else if (value == "dense")
      f.pooling = Pooling::dense;
    else
      throw bad("sparse, dense");
  } else if (knob == "fast_math") {
    if (value == "on" || value == "true")
      f.fast_math = true;
    else if (value == "off" || value == "false")
      f.fast_math = false;
    else
      throw bad("on, off");
  } else if (knob == "noise_model") {
    if (value == "per-pixel")
      f.noise = NoiseModel::per_pixel;
    else if (value == "block-mean")
      f.noise = NoiseModel::block_mean;
    else
      throw bad("per-pixel, block-mean");
  } else {
    throw InputError(where + ": unknown fidelity knob \"" + knob + "\"");
  }
}

const char* tier_name(Tier t) { return t == Tier::fast ? "fast" : t == Tier::exact ? "exact" : "standard"; }
const char* precision_name(Precision p) {
  return p == Precision::fp64 ? "fp64" : p == Precision::fixed16 ? "fixed16" : "fp32";
}

void validate(const Plan& plan, const Catalogue& cat) {
  const ModelSettings& m = plan.model;
  (void)cat;
  if (m.block < 1 || m.block > 65536)
    throw InputError("--block: " + std::to_string(m.block) + " must be between 1 and 65536 pixels");
  if (!std::isfinite(m.pixel_sigma) || m.pixel_sigma < 0 || m.pixel_sigma > 1000)
    throw InputError("--pixel-noise: must be a finite number between 0 and 1000 gray levels");
  if (!std::isfinite(m.jitter) || m.jitter < 0 || m.jitter > 1000)
    throw InputError("--jitter: must be a finite number of pixels between 0 and 1000");
  if (m.metal_noise < 0 || m.metal_noise > 199) throw InputError("--metal-noise: must be between 0 and 199");
}

}  // namespace portalsim
