#include "backend/reference/stages.h"

namespace portalsim::reference {

// The clothing surface over an object is pulled towards the object's physical temperature:
// by ir_coupling of the object's shortfall below the skin.
double contact_shadow_kelvin(const Catalogue& cat, const ModelSettings& m, int variant) {
  const PhysicsConfig& pc = cat.physics;
  return -pc.ir_coupling * (pc.skin_temperature - worn_temperature(cat, m, variant));
}

// The shadow field alone (0 K where no object lies), objects in region order by their IR
// sprites' coverage, as radiometry lays them: v = c dT + (1 - c) v.
void contact_shadow(const ViewScene& vs, Field& f) {
  f.width = vs.sensor.width;
  f.height = vs.sensor.height;
  f.v.assign(vs.sensor.pixels(), 0.0);
  lay_objects(vs, f, 1.0, [](const ViewScene& s, const Placed& p, int, int) {
    return contact_shadow_kelvin(s.cat, s.model, p.variant);
  });
}

// The bare body's surface temperature, its base image's index read linearly as kelvin,
// added to the (spread) shadow.
void ir_surface(const ViewScene& vs, Field& f) {
  const PhysicsConfig& pc = vs.cat.physics;
  const Image& base = vs.assets.bases[vs.scenario.subject][vs.view];
  const double per_index = (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) f.at(x, y) += pc.ir_index_min_k + per_index * base.at(x, y);
}

}  // namespace portalsim::reference
