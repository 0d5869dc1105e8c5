#include "scene/sensor.h"

#include <algorithm>
#include <cmath>

#include "scene/catalogue.h"

namespace portalsim {

const char* model_name(Model m) { return m == Model::physics ? "physics" : "thesis"; }

void derive_view(Catalogue& cat, Sensor& s) {
  const CameraKind& kind = camera_kind(s.camera);
  s.pattern_noise = kind.pattern_noise;
  s.palette = kind.palette;
  s.physics_chain = kind.physics_chain;
  s.jitter_scale_x = s.width / s.field.w;
  s.jitter_scale_y = s.height / s.field.h;
  s.floor_row = (kFieldHeight - s.field.y) * s.height / s.field.h;
  const SpriteSet set{s.camera, s.jitter_scale_x, s.jitter_scale_y, s.side == Side::back};
  const auto found = std::find(cat.sprite_sets.begin(), cat.sprite_sets.end(), set);
  s.sprite_set = static_cast<int>(found - cat.sprite_sets.begin());
  if (found == cat.sprite_sets.end()) cat.sprite_sets.push_back(set);
  derive_places(cat, s);
}

void derive_places(const Catalogue& cat, Sensor& s) {
  // A region's place follows the body drawn for the subject (scene/body_shape.h): a point
  // c rows above the floor is drawn c * height rows above it, and the legs' part of c also
  // scales by the leg length. Whole pixels, so that integer placement stays integer and
  // height 1 moves nothing.
  // Across, it follows the body's width at the region's centre (drawn_col), where the
  // subject's breadths are given.
  s.subject_dy.assign(cat.subjects.size(), {});
  s.subject_dx.assign(cat.subjects.size(), {});
  for (size_t k = 0; k < cat.subjects.size(); ++k)
    for (int r = 0; r < cat.region_count(); ++r) {
      const BodyShape& b = cat.subjects[k].shape;
      const double c = s.rects[r].y + s.rects[r].h / 2.0;
      const double move = b.leg_length == 1.0 ? (1.0 - b.height) * (s.floor_row - c)
                                              : (drawn_row(b, s.field_row(c)) - s.field_row(c)) * s.jitter_scale_y;
      s.subject_dy[k][r] = static_cast<int>(std::lround(move));
      const double u = s.field_col(s.rects[r].x + s.rects[r].w / 2.0);
      const double across = (drawn_col(b, u, s.field_row(c)) - u) / s.field_per_col();
      s.subject_dx[k][r] = static_cast<int>(std::lround(across));
    }
}

int first_view(const std::vector<Sensor>& views, int region) {
  for (size_t k = 0; k < views.size(); ++k)
    if (views[k].sees(region)) return static_cast<int>(k);
  return -1;
}

int first_feature_view(const std::vector<Sensor>& views, int region) {
  for (size_t k = 0; k < views.size(); ++k)
    if (views[k].sees(region) && camera_kind(views[k].camera).feature_views) return static_cast<int>(k);
  return -1;
}

int Catalogue::sensor_index(std::string_view name) const {
  for (size_t k = 0; k < sensors.size(); ++k)
    if (sensors[k].name == name) return static_cast<int>(k);
  return -1;
}

}  // namespace portalsim
