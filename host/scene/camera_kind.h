// What differs between the kinds of camera a view may belong to, declared once per kind
// (camera_mmw.cpp, camera_ir.cpp) and listed in camera_kind.cpp's registry: its name in
// the catalogue, what the catalogue accepts of its views, the flags and physics stage
// chain derive_view gives them, how its images are drawn and its physics tables filled,
// and what the features, the calibration and the reports take of it. Code asks the kind,
// not which kind it is.
#pragma once
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace portalsim {

// Which sprites and palette a view uses: the camera it belongs to (its kind's index in the
// registry). The two enumerators name the thesis's kinds for the code and tests that speak of
// them; a kind added later needs none: its value is Camera{its index}, which its file sets.
enum class Camera : int { mmw = 0, ir = 1 };

struct CameraKind {
  Camera camera;
  // The catalogue's [[views]] camera, file and column names, the objects' keys of its
  // drawings (<name>, <name>_h, <name>_v, <name>_level), transfer's --cnn-inputs name.
  const char* name;
  const char* label;                 // in messages and reports: "MMW"
  std::array<const char*, 2> nouns;  // its views in transfer's report, one and several
  double netd_max;                   // the most a view's own netd may be, K rms
  unsigned netd_knob;                // the drawn element (PS_DRAWN_*) of the knob a view's own netd replaces
  // Whether a view may have its own raw grid (raw): --mmw-raw applies to its views, and
  // calibrate fits them (their raw grid, blur, window and noise).
  bool raw_grid;
  // Its views are the features' views (the thesis's MMW): a region is listed under its view
  // (the catalogue command, the page), and validate --demo alters them.
  bool feature_views;
  bool pattern_noise;  // the thesis's noise patterns are laid over its objects
  // Stored as a temperature index, written through the palette; so also drawn as one
  // (procedural::ir_view, an object's <name>_level as an index, a file read to the nearest
  // palette colour). Else gray (procedural::mmw_view, files read as luminance).
  bool palette;
  std::vector<std::string> physics_chain;  // stages under --model physics (backend/stages.cpp)
  // The step that fills its views' physics tables (PsPhys<Kind>, physics_params.cpp's
  // registry of fills), as the chain names its stages.
  const char* physics_fill;
};

// Every kind, in the order of Camera; the kind of `c`; the kind named `name`, or null.
const std::vector<const CameraKind*>& camera_kinds();
const CameraKind& camera_kind(Camera c);
const CameraKind* camera_kind_named(std::string_view name);
// The kinds' names as a message lists them: "mmw" or "ir".
std::string camera_kind_names();
inline const char* camera_name(Camera c) { return camera_kind(c).name; }

}  // namespace portalsim
