#include "plan/plan.h"

#include <cmath>

#include "scene/error.h"

namespace portalsim {

FeatureLayout FeatureLayout::of(const Catalogue& cat, int block) {
  FeatureLayout f;
  f.block = block;
  f.blocks_x = (cat.images.mmw_width + block - 1) / block;
  f.blocks_y = (cat.images.mmw_height + block - 1) / block;
  return f;
}

std::vector<std::string> FeatureLayout::names() const {
  std::vector<std::string> n;
  for (const char* view : {"upper", "lower"})
    for (int by = 0; by < blocks_y; ++by)
      for (int bx = 0; bx < blocks_x; ++bx)
        n.push_back(std::string(view) + "_r" + std::to_string(by) + "_c" + std::to_string(bx));
  for (int r = 1; r <= kRegions; ++r) n.push_back("region" + std::to_string(r));
  for (int z = 1; z <= kZones; ++z) n.push_back("zone" + std::to_string(z));
  return n;
}

void validate(const Plan& plan, const Catalogue& cat) {
  const ModelSettings& m = plan.model;
  const int side = std::max(cat.images.mmw_width, cat.images.mmw_height);
  if (m.block < 1 || m.block > side)
    throw InputError("--block: " + std::to_string(m.block) + " must be between 1 and the image side (" +
                     std::to_string(side) + ")");
  if (!std::isfinite(m.pixel_sigma) || m.pixel_sigma < 0 || m.pixel_sigma > 1000)
    throw InputError("--pixel-noise: must be a finite number between 0 and 1000 gray levels");
  if (m.metal_noise < 0 || m.metal_noise > 199)
    throw InputError("--metal-noise: must be between 0 and 199");
}

}  // namespace portalsim
