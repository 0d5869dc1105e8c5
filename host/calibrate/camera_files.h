// What calibrate writes for `generate`: a spec of the fitted knobs (the window among them)
// and a copy of the catalogue with the fitted aperture.
#pragma once
#include <string>

#include "calibrate/fit.h"

namespace portalsim::calibrate {

// The spec (TOML): model, netd, mmw_raw, illumination, the fitted window and every camera
// knob the fit assumed, each written out (`generate --spec`).
std::string camera_spec(const CameraFit& fit, const ModelSettings& model, const std::string& spec_name,
                        const std::string& catalogue_name);

// `catalogue_text` with [physics]'s aperture_m set to the fit
// (each key's line replaced, or added after [physics] where missing).
std::string camera_catalogue(const std::string& catalogue_text, const CameraFit& fit);

}  // namespace portalsim::calibrate
