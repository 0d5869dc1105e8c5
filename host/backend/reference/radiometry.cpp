#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

namespace {

// What a surface of emissivity e at physical temperature t shows the camera under
// clothing: it emits e t and reflects the illumination, (1 - e) T_ill; the clothing passes
// a fraction tc of that and emits its own (1 - tc) T_clothing.
double under_clothing(const PhysicsConfig& pc, const ModelSettings& m, double e, double t) {
  const double surface = e * t + (1.0 - e) * m.illumination;
  return pc.clothing_transmission * surface + (1.0 - pc.clothing_transmission) * pc.clothing_temperature;
}

}  // namespace

double body_temperature(const Catalogue& cat, const ModelSettings& m, const Subject& subject) {
  const PhysicsConfig& pc = cat.physics;
  return under_clothing(pc, m, pc.skin_emissivity_of(subject), pc.skin_temperature_of(subject));
}

// The object has warmed from the room towards the skin it lies on for worn_minutes, with its
// material's time constant.
double worn_temperature(const Catalogue& cat, const ModelSettings& m, int variant, double skin) {
  const PhysicsConfig& pc = cat.physics;
  const Material& mat = cat.materials.at(cat.object_of(variant).material_id);
  return skin - (skin - pc.room_temperature) * std::exp(-m.worn_minutes / mat.warm_minutes);
}

// In MMW the object warms towards the catalogue's skin (docs/model/bodies.md).
double object_temperature(const Catalogue& cat, const ModelSettings& m, int variant) {
  const Material& mat = cat.materials.at(cat.object_of(variant).material_id);
  return under_clothing(cat.physics, m, mat.emissivity,
                        worn_temperature(cat, m, variant, cat.physics.skin_temperature));
}

// The subject's base image in kelvin: its background gray is the room behind the subject,
// its mmw_level the bare body under clothing, linear in between (and beyond, so a real
// capture's texture carries over).
void radiometry(const ViewScene& vs, Field& f) {
  const PhysicsConfig& pc = vs.cat.physics;
  const Image& base = vs.assets.bases[vs.scenario.subject][vs.view];
  const Subject& subject = vs.cat.subjects[vs.scenario.subject];
  const double g0 = pc.base_background_gray, g1 = subject.mmw_level;
  const double t0 = pc.background_temperature, t1 = body_temperature(vs.cat, vs.model, subject);
  f.width = base.width;
  f.height = base.height;
  f.v.assign(static_cast<size_t>(f.width) * f.height, 0.0);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) f.at(x, y) = t0 + (base.at(x, y) - g0) / (g1 - g0) * (t1 - t0);
  lay_objects(vs, f, 1.0, [](const ViewScene& s, const Placed& p, int, int) {
    return object_temperature(s.cat, s.model, p.variant);
  });
}

}  // namespace portalsim::reference
