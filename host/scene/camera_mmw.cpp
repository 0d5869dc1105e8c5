// The passive MMW camera (docs/model/physics-mmw.md): gray images, the thesis's noise
// patterns, and a raw grid sampled, averaged over frames and windowed for display.
#include "contract.h"
#include "scene/camera_kind.h"

namespace portalsim {

const CameraKind& mmw_camera() {
  static const CameraKind kind{
      .camera = Camera::mmw,
      .name = "mmw",
      .label = "MMW",
      .nouns = {"views", "views"},
      .netd_max = 100.0,
      .netd_knob = PS_DRAWN_NETD,
      .raw_grid = true,
      .feature_views = true,
      .pattern_noise = true,
      .palette = false,
      .physics_chain = {"radiometry", "optics", "sample", "netd", "window", "mmw_display"},
      .physics_fill = "mmw_raw_grid",
  };
  return kind;
}

}  // namespace portalsim
