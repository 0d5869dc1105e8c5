// What differs between the kinds of camera a view may belong to, declared once per kind
// (camera_mmw.cpp, camera_ir.cpp) and listed in camera_kind.cpp's registry: its name in
// the catalogue, what the catalogue accepts of its views, and the flags and physics stage
// chain derive_view gives them. Code asks the kind, not which kind it is.
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace portalsim {

// Which sprites and palette a view uses: the camera it belongs to (its kind's index in the
// registry).
enum class Camera : int { mmw = 0, ir = 1 };

struct CameraKind {
  Camera camera;
  const char* name;                        // the catalogue's [[views]] camera, and file and column names
  double netd_max;                         // the most a view's own netd may be, K rms
  bool raw_grid;                           // whether a view may have its own raw grid (raw)
  bool pattern_noise;                      // the thesis's noise patterns are laid over its objects
  bool palette;                            // stored as a temperature index, written through the palette
  std::vector<std::string> physics_chain;  // stages under --model physics (backend/stages.cpp)
};

// Each kind's declaration (one file each).
const CameraKind& mmw_camera();
const CameraKind& ir_camera();

// Every kind, in the order of Camera; the kind of `c`; the kind named `name`, or null.
const std::vector<const CameraKind*>& camera_kinds();
const CameraKind& camera_kind(Camera c);
const CameraKind* camera_kind_named(std::string_view name);
// The kinds' names as a message lists them: "mmw" or "ir".
std::string camera_kind_names();
inline const char* camera_name(Camera c) { return camera_kind(c).name; }

}  // namespace portalsim
