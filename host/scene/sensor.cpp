#include "scene/sensor.h"

#include <cmath>

#include "scene/catalogue.h"

namespace portalsim {

const char* model_name(Model m) { return m == Model::physics ? "physics" : "thesis"; }

std::vector<Sensor> camera_sensors(const Catalogue& cat) {
  const ImagesConfig& ic = cat.images;
  std::vector<Sensor> out;
  for (View view : {View::upper, View::lower}) {
    Sensor s;
    s.name = view == View::upper ? "upper" : "lower";
    s.asset_key = "mmw_" + s.name;
    s.camera = Camera::mmw;
    s.width = ic.mmw_width;
    s.height = ic.mmw_height;
    s.floor_row = view == View::upper ? 2.0 * ic.mmw_height : ic.mmw_height;
    for (const Region& r : cat.regions)
      if (r.view == view) {
        s.rects[r.id - 1] = r.mmw;
        s.region_mask |= 1u << (r.id - 1);
      }
    s.pattern_noise = true;
    s.pooled = true;
    s.physics_chain = {"radiometry", "optics", "sample", "netd", "window", "mmw_display"};
    out.push_back(s);
  }
  // The IR camera sees the whole body at its own scale: the two MMW views stacked.
  Sensor ir;
  ir.name = "ir";
  ir.asset_key = "ir";
  ir.camera = Camera::ir;
  ir.width = ic.ir_width;
  ir.height = ic.ir_height;
  ir.floor_row = ic.ir_height;
  for (const Region& r : cat.regions) {
    ir.rects[r.id - 1] = r.ir;
    ir.region_mask |= 1u << (r.id - 1);
  }
  ir.palette = true;
  ir.physics_chain = {"contact_shadow", "heat_spread", "ir_surface", "ir_netd", "ir_display"};
  ir.jitter_scale_x = static_cast<double>(ic.ir_width) / ic.mmw_width;
  ir.jitter_scale_y = static_cast<double>(ic.ir_height) / (2.0 * ic.mmw_height);
  out.push_back(ir);
  // A region's place follows the body drawn for the subject (procedural::Body::height): a
  // point c rows above the floor is drawn c * height rows above it. Whole pixels, so that
  // integer placement stays integer and height 1 moves nothing.
  for (Sensor& s : out) {
    s.subject_dy.assign(cat.subjects.size(), {});
    for (size_t k = 0; k < cat.subjects.size(); ++k)
      for (int r = 0; r < kRegions; ++r) {
        const double c = s.rects[r].y + s.rects[r].h / 2.0;
        s.subject_dy[k][r] = static_cast<int>(std::lround((1.0 - cat.subjects[k].height) * (s.floor_row - c)));
      }
  }
  return out;
}

int Catalogue::sensor_index(std::string_view name) const {
  for (size_t k = 0; k < sensors.size(); ++k)
    if (sensors[k].name == name) return static_cast<int>(k);
  return -1;
}

}  // namespace portalsim
