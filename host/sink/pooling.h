// Block and region means of camera images on the host, as the kernels compute them
// (kernels/pool.cl: integer sums, quotient and remainder divided in float), so that rows
// made from image files equal generate's rows. The one pooling on the host; the CPU
// reference keeps its own fp64 loops (backend/reference/pool.cpp), being the check.
#pragma once
#include <vector>

#include "assets/assets.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim {

// The image features of one scenario into row[0 .. lay.image_features()): the blocks of
// each pooled view, then each region's mean in the first pooled view that sees it (0 where
// none does). images[slot] is pooled view lay.pooled[slot], 8-bit gray at its sensor's size.
void pool_images(const Catalogue& cat, const FeatureLayout& lay, const std::vector<Image>& images, float* row);

}  // namespace portalsim
