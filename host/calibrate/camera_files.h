// What calibrate writes for `generate`: a spec of the fitted knobs (the window among them)
// and a copy of the catalogue with the fitted aperture and the views' own cameras.
#pragma once
#include <string>

#include "calibrate/fit.h"

namespace portalsim::calibrate {

// The spec (TOML): model, netd, mmw_raw, illumination, the fitted window and every camera
// knob the fit assumed, each written out (`generate --spec`).
std::string camera_spec(const CameraFit& fit, const ModelSettings& model, const std::string& spec_name,
                        const std::string& catalogue_name);

// `catalogue_text` with [physics]'s aperture_m set to the fit, and each fitted view's
// [[views]] entry given its own `raw` and `netd` where the fit gives it a camera of its own
// (ViewFit::own_raw, own_netd) and neither where it follows the run's. Each key's line is
// replaced, or added after the table's last key where missing; the rest, comments
// included, is kept. Throws InputError naming `source` where a view that needs its own
// camera has no entry to be found in the text.
std::string camera_catalogue(const std::string& catalogue_text, const CameraFit& fit, const std::string& source);

}  // namespace portalsim::calibrate
