// Each fidelity tier's stated tolerance against the fp64 CPU reference. Tests hold the
// kernels to these; `portalsim tradeoff` reports where each tier actually lands.
#pragma once
#include <string>

#include "backend/compare.h"
#include "plan/plan.h"

namespace portalsim {

struct Tolerance {
  int pixel_max_abs;             // gray levels (MMW) and temperature index (IR)
  double pixel_share_differing;  // share of pixels that may differ at all
  double feature_max_abs;        // without the block-mean noise model
  double feature_mean_abs;
  // Metal zones and labels are integers and match exactly in every tier.
};

inline Tolerance tier_tolerance(Tier t) {
  switch (t) {
    case Tier::exact:  // fp64: only x.5 ties resolved by last-bit differences may differ
      return {1, 1e-4, 0.011, 1e-4};
    case Tier::standard:  // fp32: ties and fp32 rounding
      return {1, 1e-3, 1.0, 0.01};
    case Tier::fast:  // 8.8 fixed point: alpha and noise gain quantised to 1/256
      return {2, 0.5, 2.0, 0.5};
  }
  return {0, 0, 0, 0};
}

// Empty when `d` is within `t` (features checked only where present); else what broke.
inline std::string check_tolerance(const OutputDiff& d, const Tolerance& t) {
  std::string why;
  for (auto [name, img] : {std::pair{"MMW", &d.mmw}, std::pair{"IR", &d.ir}}) {
    if (img->max_abs > t.pixel_max_abs)
      why += std::string(name) + " max abs " + std::to_string(img->max_abs) + " > " + std::to_string(t.pixel_max_abs) +
             "; ";
    if (img->share_differing > t.pixel_share_differing)
      why += std::string(name) + " share differing " + std::to_string(img->share_differing) + " > " +
             std::to_string(t.pixel_share_differing) + "; ";
  }
  if (d.feature_max_abs > t.feature_max_abs)
    why += "feature max abs " + std::to_string(d.feature_max_abs) + " > " + std::to_string(t.feature_max_abs) + "; ";
  if (d.feature_mean_abs > t.feature_mean_abs)
    why += "feature mean abs " + std::to_string(d.feature_mean_abs) + " > " + std::to_string(t.feature_mean_abs) + "; ";
  if (d.metal_exact < 1.0) why += "metal zones differ; ";
  return why;
}

}  // namespace portalsim
