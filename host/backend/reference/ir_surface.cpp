#include "backend/reference/stages.h"

namespace portalsim::reference {

namespace {

// The bare surface's temperature at (x, y): the subject's base image index read linearly
// as kelvin.
double base_kelvin(const ViewScene& vs, int x, int y) {
  const PhysicsConfig& pc = vs.cat.physics;
  const Image& base = vs.assets.bases[vs.scenario.subject][vs.view];
  return pc.ir_index_min_k + (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0 * base.at(x, y);
}

// How much of an object's shortfall reaches the clothing surface: the catalogue's
// ir_coupling, or under an outfit its surface's share.
double coupling(const Catalogue& cat, const ModelSettings& m) {
  return m.outfit < 0 ? cat.physics.ir_coupling : outfit_surface_share(m);
}

// Where the object lies off the body, the surface it touches is the room's.
double off_body_shadow_kelvin(const Catalogue& cat, const ModelSettings& m, int variant, const Subject& subject) {
  const PhysicsConfig& pc = cat.physics;
  return -coupling(cat, m) * (pc.room_temperature - worn_temperature(cat, m, variant, pc.skin_temperature_of(subject)));
}

}  // namespace

// The clothing surface over an object is pulled towards the object's physical temperature:
// by ir_coupling of the object's shortfall below the subject's skin, which it warms towards.
double contact_shadow_kelvin(const Catalogue& cat, const ModelSettings& m, int variant, const Subject& subject) {
  const double skin = cat.physics.skin_temperature_of(subject);
  return -coupling(cat, m) * (skin - worn_temperature(cat, m, variant, skin));
}

// The shadow field alone (0 K where no object lies), objects in region order by their IR
// sprites' coverage, as radiometry lays them: v = c dT + (1 - c) v; dT against the skin
// where the base image is body (warmer than halfway from the room to the skin), against the
// room elsewhere.
void contact_shadow(const ViewScene& vs, Field& f) {
  f.width = vs.sensor.width;
  f.height = vs.sensor.height;
  f.v.assign(vs.sensor.pixels(), 0.0);
  Field off = f;
  lay_objects(vs, f, 1.0, [](const ViewScene& s, const Placed& p, int, int) {
    return contact_shadow_kelvin(s.cat, s.model, p.variant, s.cat.subjects[s.scenario.subject]);
  });
  lay_objects(vs, off, 1.0, [](const ViewScene& s, const Placed& p, int, int) {
    return off_body_shadow_kelvin(s.cat, s.model, p.variant, s.cat.subjects[s.scenario.subject]);
  });
  const PhysicsConfig& pc = vs.cat.physics;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      if (base_kelvin(vs, x, y) < (pc.room_temperature + pc.skin_temperature) / 2) f.at(x, y) = off.at(x, y);
}

// The bare body's surface temperature, its base image's index read linearly as kelvin,
// added to the (spread) shadow. Under an outfit the base image is the bare skin's, and the
// outfit's surface keeps its share of that above the room.
void ir_surface(const ViewScene& vs, Field& f) {
  const double room = vs.cat.physics.room_temperature;
  const bool dressed = vs.model.outfit >= 0;
  const double share = dressed ? outfit_surface_share(vs.model) : 1.0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      f.at(x, y) += dressed ? room + share * (base_kelvin(vs, x, y) - room) : base_kelvin(vs, x, y);
  // Folds and seams: over the share m of a pixel where the outer garment lies doubled, the
  // surface keeps the share with its resistance counted twice; the surface (and its shadow)
  // is the mix of the two.
  if (!dressed || vs.model.clothing_folds == 0) return;
  const double doubled = outfit_surface_share(vs.model, true);
  const Image& folds = vs.assets.folds.at(static_cast<size_t>(vs.scenario.subject)).at(static_cast<size_t>(vs.view));
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const double m = vs.model.clothing_folds * folds.at(x, y) / 255.0;
      f.at(x, y) = room + ((1 - m) * share + m * doubled) / share * (f.at(x, y) - room);
    }
}

}  // namespace portalsim::reference
