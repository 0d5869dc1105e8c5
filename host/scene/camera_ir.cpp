// The IR camera (docs/model/physics-ir.md): temperature indices through the palette, the
// objects' contact shadows on the skin spread by heat, and the camera's own display window.
#include "scene/camera_kind.h"

namespace portalsim {

const CameraKind& ir_camera() {
  static const CameraKind kind{
      .camera = Camera::ir,
      .name = "ir",
      .netd_max = 10.0,
      .raw_grid = false,
      .pattern_noise = false,
      .palette = true,
      .physics_chain = {"contact_shadow", "heat_spread", "ir_surface", "ir_netd", "ir_display"},
  };
  return kind;
}

}  // namespace portalsim
