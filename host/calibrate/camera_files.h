// What calibrate writes for `generate`: a spec of the fitted knobs and a copy of the
// catalogue with the fitted window and aperture.
#pragma once
#include <string>

#include "calibrate/fit.h"

namespace portalsim::calibrate {

// The spec (TOML): model, netd, mmw_raw, illumination and every camera knob the fit
// assumed, each written out (`generate --spec`).
std::string camera_spec(const CameraFit& fit, const ModelSettings& model, const std::string& spec_name,
                        const std::string& catalogue_name);

// `catalogue_text` with [physics]'s display_min, display_max and aperture_m set to the fit
// (each key's line replaced, or added after [physics] where missing).
std::string camera_catalogue(const std::string& catalogue_text, const CameraFit& fit);

}  // namespace portalsim::calibrate
