// The passive MMW camera (docs/model/physics-mmw.md): gray images, the thesis's noise
// patterns, and a raw grid sampled, averaged over frames and windowed for display.
#include "scene/camera_kind.h"

namespace portalsim {

const CameraKind& mmw_camera() {
  static const CameraKind kind{
      .camera = Camera::mmw,
      .name = "mmw",
      .netd_max = 100.0,
      .raw_grid = true,
      .pattern_noise = true,
      .palette = false,
      .physics_chain = {"radiometry", "optics", "sample", "netd", "window", "mmw_display"},
  };
  return kind;
}

}  // namespace portalsim
