// The catalogue on the device, uploaded once per backend: the image atlas (bases, sprites,
// noise tiles and their padded copies), the sprites' places in each view, the pooled
// views' rectangles and the metal detector's tables. Every path reads these.
#pragma once
#include <CL/opencl.hpp>
#include <vector>

#include "assets/assets.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim::opencl {

struct DeviceCatalogue {
  DeviceCatalogue(const Catalogue& cat, const AssetSet& assets, cl::Context& ctx);

  cl::Buffer atlas, bases, sprites, places, noise_offsets, noise_gains;
  cl::Buffer pooled, region_slot, region_rects;  // per region: its pooled slot and rectangle there
  std::vector<cl::Buffer> view_rects;            // per view: int4 per region
  cl::Buffer influence, categories, base_zones;  // the thesis's metal detector
  // Per sprite set, each variant's sprite: atlas offset, width, height, padded offset.
  std::vector<cl_int4> sprite_records;
  const cl_int4& sprite(const Sensor& view, size_t variant) const {
    return sprite_records[view.sprite_set * variants + variant];
  }
  size_t variants = 0;
};

// A sprite centred in a region's rectangle (>> 1 floors negative differences too): where
// place_view lays it without jitter, given the region's place on the subject.
Rect sprite_box(const Rect& rc, const Image& sprite);

// The pooled slot whose view sees region r (the first), 0 where none does.
int region_slot(const Catalogue& cat, const FeatureLayout& lay, int r);

}  // namespace portalsim::opencl
