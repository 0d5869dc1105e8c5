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
  // Sprite placement: each object moves by jitter * (2u - 1) pixels in x and y (u from
  // the counter generator), rounded to whole pixels, or kept sub-pixel with bilinear
  // sampling. The noise tiles stay where the unmoved sprite would be.
  bool bilinear = false;
  double jitter = 0.0;
  bool moves_sprites() const { return bilinear || jitter > 0; }
};

// How block and region means are computed. Both give the same numbers to the bit
// (under -cl-fast-relaxed-math, to the division's approximation); sparse is used for
// features-only runs without per-pixel noise, dense otherwise.
enum class Pooling { sparse, dense };
// The arithmetic of the kernels' pixel values.
enum class Precision { fp32, fp64, fixed16 };
// Per-pixel sensor noise, or (features-only runs) its effect on each mean drawn
// directly: N(0, sigma^2 / pixels), ignoring rounding and clipping.
enum class NoiseModel { per_pixel, block_mean };

// The speed/accuracy knobs of the OpenCL backend (README, "Fidelity tiers"). None of
// them changes what is modelled; each changes how closely the kernels follow the fp64
// reference, and how fast.
struct Fidelity {
  Precision precision = Precision::fp32;
  Pooling pooling = Pooling::sparse;
  bool fast_math = false;  // -cl-fast-relaxed-math
  NoiseModel noise = NoiseModel::per_pixel;
};

enum class Tier { fast, standard, exact };
Fidelity tier_fidelity(Tier t);
Tier parse_tier(const std::string& name, const std::string& where);
// Sets one knob by name ("precision", "pooling", "fast_math", "noise_model") from text;
// throws InputError naming `where`.
void set_fidelity_knob(Fidelity& f, const std::string& knob, const std::string& value, const std::string& where);
const char* tier_name(Tier t);
const char* precision_name(Precision p);

struct Plan {
  bool mmw_images = true;  // materialise upper/lower images
  bool ir_image = true;    // materialise the IR image
  bool metal = true;       // metal zones
  bool features = true;    // block and region means (needs the MMW views)
  ModelSettings model;
  Fidelity fidelity;

  // Per-pixel noise drawn pixel by pixel (otherwise none, or the block-mean model).
  bool pixel_noise_per_pixel() const {
    return model.pixel_sigma > 0 && (mmw_images || ir_image || fidelity.noise == NoiseModel::per_pixel);
  }
  // Features straight from precomputed tables, never materialising an image. Block sums
  // must stay exact in fp32 (255 * 256^2 < 2^24).
  bool sparse_features() const {
    return features && !mmw_images && fidelity.pooling == Pooling::sparse && !pixel_noise_per_pixel() &&
           model.block <= 256 && !model.moves_sprites();
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
