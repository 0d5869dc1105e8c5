#include "backend/backend.h"

namespace portalsim {

void prepare_output(BatchOutput& out, const Catalogue& cat, const Plan& plan, size_t n) {
  const ImagesConfig& ic = cat.images;
  out.n = n;
  out.mmw_width = ic.mmw_width;
  out.mmw_height = ic.mmw_height;
  out.ir_width = ic.ir_width;
  out.ir_height = ic.ir_height;
  out.layout = FeatureLayout::of(cat, plan.model.block);
  const size_t mmw_px = static_cast<size_t>(ic.mmw_width) * ic.mmw_height;
  const size_t ir_px = static_cast<size_t>(ic.ir_width) * ic.ir_height;
  out.upper.resize(plan.mmw_images ? n * mmw_px : 0);
  out.lower.resize(plan.mmw_images ? n * mmw_px : 0);
  out.ir.resize(plan.ir_image ? n * ir_px : 0);
  out.metal.resize(plan.metal ? n * kZones : 0);
  out.features.resize(plan.features ? n * out.layout.image_features() : 0);
}

}  // namespace portalsim
