// The camera's parameters fitted to its captures (`portalsim calibrate`). The captures are
// taken to show the catalogue's subjects (the built-in ones, or a user's own base images),
// each under the physics model's radiometry; what is fitted is the camera: its raw grid,
// its blur (the PSF's FWHM, hence the aperture), its display window and its noise.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "calibrate/captures.h"
#include "calibrate/raw_grid.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim::calibrate {

// One MMW view's own camera: its raw grid and its noise, from its own captures alone.
struct ViewFit {
  std::string name;  // the catalogue's view
  GridAxis grid_x, grid_y;
  int raw_w = 0, raw_h = 0;
  // Noise per raw pixel from this view's cells alone, in gray levels and in kelvin, and the
  // standard error of the gray figure: each capture's own spread, scattered over the captures.
  double noise_gray = 0, netd = 0, noise_se = 0;
  bool noise_agrees = true;  // one camera's noise with the run view's (kNoiseAgreement below)
  int cells = 0;             // raw cells fitted
  // Whether camera.catalogue.toml gives this view its own raw grid or NETD: where it
  // differs from the run's, or where the catalogue already gave the view its own.
  bool own_raw = false, own_netd = false;
};

// Noise under this many gray levels per raw pixel: quieter than any camera (rendered
// images, such as the thesis model's, have next to none).
inline constexpr double kMinCameraNoiseGray = 0.1;

// Two views' noise is one camera's unless it differs by more than kNoiseAgreement standard
// errors of the difference (the captures' scatter), by more than kNoiseTolerance of the run
// view's, and by more than kMinCameraNoiseGray. The views of one camera, fitted apart,
// differ by up to about 6% where the window clips (clipped cells are left out, more in one
// view than another), beyond their standard errors; 10% is what calibrate is held to
// (tests/calibrate_test.cpp); under a tenth of a gray level is rounding, not a camera.
inline constexpr double kNoiseAgreement = 3.0;
inline constexpr double kNoiseTolerance = 0.10;

struct CameraFit {
  std::vector<ViewFit> views;  // the captures' views, in their order
  // The run's camera (camera.toml's mmw_raw and netd). Its raw grid is the first view's that
  // the catalogue gives no raw grid of its own (raw_view; the first view where all have one).
  // Its noise is pooled over the views whose own noise agrees with noise_view's (the first
  // view the catalogue gives no NETD of its own), so that one camera's views share it.
  size_t raw_view = 0, noise_view = 0;
  int raw_w = 0, raw_h = 0;
  double noise_gray = 0, netd = 0;
  // Blur: the PSF's FWHM in view pixels and the aperture that gives it (1.02 lambda / D).
  double fwhm_pixels = 0, aperture_m = 0;
  bool blur_told = true;                     // false: the captures hardly change with the blur
  std::vector<double> blur_fwhm, blur_cost;  // the search, for the report
  // Display window: gray = gain (T - display_min), gain = 255 / (max - min).
  double display_min = 0, display_max = 0, gain = 0;
  double gain_rel_error = 0;  // the gain's standard error over the gain
  bool window_told = true;    // false: the model's window width kept, its level fitted
  // Per capture, the catalogue subject (0-based) it was matched to.
  std::vector<int> subject;
  int cells = 0;  // raw cells fitted, all views

  // What generate takes for view v: its own raw grid and NETD where own_raw / own_netd,
  // else the run's. A view whose noise agrees with the run's takes the run's pooled NETD.
  std::array<int, 2> view_raw(size_t v) const {
    return views[v].own_raw ? std::array<int, 2>{views[v].raw_w, views[v].raw_h} : std::array<int, 2>{raw_w, raw_h};
  }
  double view_netd(size_t v) const { return views[v].noise_agrees ? netd : views[v].netd; }
  double view_noise_gray(size_t v) const { return views[v].noise_agrees ? noise_gray : views[v].noise_gray; }
};

// Fits the camera to `captures`: each view's raw grid and noise from its own captures, the
// blur and the window from all of them. `cat` and `assets` give the scene (subjects,
// radiometry, frequency, range, field of view) and which views have a camera of their own
// (Sensor::raw, Sensor::netd: refitted, not used); `model` its illumination and worn time.
CameraFit fit_camera(const Captures& captures, const Catalogue& cat, const AssetSet& assets,
                     const ModelSettings& model);

// Why `fit` does not look like a raw-grid camera's, or "" where it does: a view's raw grid is
// the view's own size (no coarser grid reproduces the images, so they were not interpolated
// from one), or a view's camera's noise (CameraFit::view_noise_gray) is under
// kMinCameraNoiseGray. `calibrate` refuses such captures unless
// told to fit them anyway (--accept-non-camera).
std::string not_camera_like(const Captures& captures, const CameraFit& fit);

// The aperture (m) whose Airy core is `fwhm_pixels` wide in a view `width` pixels across.
double aperture_for_fwhm(const Catalogue& cat, int width, double fwhm_pixels);

// A copy of `cat` with the fitted aperture, and each view's own raw grid and NETD where the
// fit gives it one (ViewFit::own_raw, own_netd; cleared where it does not).
Catalogue fitted_catalogue(const Catalogue& cat, const CameraFit& fit);
// `model` with the fitted NETD, raw grid and window, under the physics model, with the
// camera the fit assumes (one frame, bilinear display, no smoothing).
ModelSettings fitted_model(const ModelSettings& model, const CameraFit& fit);

}  // namespace portalsim::calibrate
