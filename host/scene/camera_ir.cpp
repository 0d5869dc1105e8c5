// The IR camera (docs/model/physics-ir.md): temperature indices through the palette, the
// objects' contact shadows on the skin spread by heat, and the camera's own display window.
#include "contract.h"
#include "scene/camera_kind.h"

namespace portalsim {

const CameraKind& ir_camera() {
  static const CameraKind kind{
      .camera = Camera::ir,
      .name = "ir",
      .label = "IR",
      .nouns = {"image", "images"},
      .netd_max = 10.0,
      .netd_knob = PS_DRAWN_IR_NETD,
      .raw_grid = false,
      .feature_views = false,
      .pattern_noise = false,
      .palette = true,
      .physics_chain = {"contact_shadow", "heat_spread", "ir_surface", "ir_netd", "ir_display"},
      .physics_fill = "ir_surface",
  };
  return kind;
}

}  // namespace portalsim
