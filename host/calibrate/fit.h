// The camera's parameters fitted to its captures (`portalsim calibrate`). The captures are
// taken to show the catalogue's subjects (the built-in ones, or a user's own base images),
// each under the physics model's radiometry; what is fitted is the camera: its raw grid,
// its blur (the PSF's FWHM, hence the aperture), its display window and its noise.
#pragma once
#include <string>
#include <vector>

#include "assets/assets.h"
#include "calibrate/captures.h"
#include "calibrate/raw_grid.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim::calibrate {

struct CameraFit {
  // Raw grid: the fewest raw pixels whose interpolation reproduces the images to rounding.
  GridAxis grid_x, grid_y;
  int raw_w = 0, raw_h = 0;
  // Blur: the PSF's FWHM in view pixels and the aperture that gives it (1.02 lambda / D).
  double fwhm_pixels = 0, aperture_m = 0;
  bool blur_told = true;                     // false: the captures hardly change with the blur
  std::vector<double> blur_fwhm, blur_cost;  // the search, for the report
  // Display window: gray = gain (T - display_min), gain = 255 / (max - min).
  double display_min = 0, display_max = 0, gain = 0;
  double gain_rel_error = 0;  // the gain's standard error over the gain
  bool window_told = true;    // false: the model's window width kept, its level fitted
  // Noise: per raw pixel, in gray levels and in kelvin (the NETD).
  double noise_gray = 0, netd = 0;
  // Per capture, the catalogue subject (0-based) it was matched to.
  std::vector<int> subject;
  int cells = 0;  // raw cells fitted
};

// Fits the camera to `captures`. `cat` and `assets` give the scene (subjects, radiometry,
// frequency, range, field of view); `model` its illumination and worn time.
CameraFit fit_camera(const Captures& captures, const Catalogue& cat, const AssetSet& assets,
                     const ModelSettings& model);

// Noise under this many gray levels per raw pixel: quieter than any camera (rendered
// images, such as the thesis model's, have next to none).
inline constexpr double kMinCameraNoiseGray = 0.1;

// Why `fit` does not look like a raw-grid camera's, or "" where it does: its raw grid is the
// view's own size (no coarser grid reproduces the images, so they were not interpolated from
// one), or its noise is under kMinCameraNoiseGray. `calibrate` refuses such captures unless
// told to fit them anyway (--accept-non-camera).
std::string not_camera_like(const Captures& captures, const CameraFit& fit);

// The aperture (m) whose Airy core is `fwhm_pixels` wide in a view `width` pixels across.
double aperture_for_fwhm(const Catalogue& cat, int width, double fwhm_pixels);

// A copy of `cat` with the fitted aperture.
Catalogue fitted_catalogue(const Catalogue& cat, const CameraFit& fit);
// `model` with the fitted NETD, raw grid and window, under the physics model, with the
// camera the fit assumes (one frame, bilinear display, no smoothing).
ModelSettings fitted_model(const ModelSettings& model, const CameraFit& fit);

}  // namespace portalsim::calibrate
