// What a batch needs: which sensors, images or features only, and the model's knobs.
// Both backends read the same Plan; what it leaves out is never computed.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "scene/catalogue.h"

namespace portalsim {

// The knobs of the sensor model (README, "The model"). Defaults are the thesis's.
struct ModelSettings {
  uint64_t seed = 0;
  bool pattern_noise = true;  // thesis 4.2: one of the MMW noise patterns over each object
  double pixel_sigma = 0.0;   // per-pixel Gaussian sensor noise, gray levels (MMW and IR)
  int metal_noise = 0;        // detector noise: triangular integer noise, half-width in counts
  int block = 10;             // side of the averaged pixel blocks (thesis 5.6)
};

// How block and region means are computed. Both give the same numbers to the bit;
// sparse is used for features-only runs without per-pixel noise, dense otherwise.
enum class Pooling { sparse, dense };

struct Plan {
  bool mmw_images = true;  // materialise upper/lower images
  bool ir_image = true;    // materialise the IR image
  bool metal = true;       // metal zones
  bool features = true;    // block and region means (needs the MMW views)
  ModelSettings model;
  Pooling pooling = Pooling::sparse;

  // Features straight from precomputed tables, never materialising an image.
  bool sparse_features() const {
    return features && !mmw_images && pooling == Pooling::sparse && model.pixel_sigma == 0;
  }
  bool renders_mmw() const { return mmw_images || features; }
};

// The layout of a feature row: upper blocks, lower blocks (row-major, partial blocks at
// the right and bottom edges averaged over the pixels they hold), the 13 region means,
// then the 19 metal zones; sinks append the class.
struct FeatureLayout {
  int block = 10;
  int blocks_x = 0, blocks_y = 0;  // per MMW view
  int image_features() const { return 2 * blocks_x * blocks_y + kRegions; }
  int row_features() const { return image_features() + kZones; }
  std::vector<std::string> names() const;
  static FeatureLayout of(const Catalogue& cat, int block);
};

// Checks the plan's numbers; throws InputError naming the option.
void validate(const Plan& plan, const Catalogue& cat);

}  // namespace portalsim
