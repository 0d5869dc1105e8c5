// The captures beside the fitted camera's own images: calibrate's report. The fitted
// camera renders each capture's matched subject (bare) through the physics model's
// reference chain; both sets are then summed up the same way.
#pragma once
#include <nlohmann/json.hpp>

#include "calibrate/fit.h"

namespace portalsim::calibrate {

// Per view: the fitted camera's image of each capture's subject, noise drawn with `seed`
// and the capture's index (as generate draws it), and the same without noise.
struct Simulated {
  std::vector<std::vector<std::vector<uint8_t>>> noisy, clean;  // [view][capture]
};
Simulated simulate_captures(const Captures& captures, const CameraFit& fit, const Catalogue& cat,
                            const AssetSet& assets, const ModelSettings& model, uint64_t seed);

// Histograms of gray levels (256 bins, fractions), noise power spectra along rows
// (the image less the fitted camera's noise-free image, gray^2 per frequency bin, 0 to
// the Nyquist limit) and edge profiles across the body's left outline (mean gray at -24..24
// pixels from where the noise-free image crosses halfway between room and body, over the
// rows of the view's middle third), for the captures ("real") and the simulation ("sim").
nlohmann::json compare_statistics(const Captures& captures, const Simulated& sim);

}  // namespace portalsim::calibrate
