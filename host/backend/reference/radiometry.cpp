#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

namespace {

// What a surface of emissivity e at physical temperature t shows the camera under
// clothing: it emits e t and reflects the illumination, (1 - e) T_ill; the catalogue's
// clothing passes a fraction tc of that and emits its own (1 - tc) T_clothing. Under an
// outfit, each layer from the skin outwards does the same at its own transmission and
// temperature (outfit_layers).
double under_clothing(const PhysicsConfig& pc, const ModelSettings& m, double e, double t) {
  double seen = e * t + (1.0 - e) * m.illumination;
  if (m.outfit < 0) return pc.clothing_transmission * seen + (1.0 - pc.clothing_transmission) * pc.clothing_temperature;
  for (const LayerSeen& layer : outfit_layers(pc, m))
    seen = layer.transmission * seen + (1.0 - layer.transmission) * layer.temperature;
  return seen;
}

// The scenario's outfit (m.outfit, as at_scenario resolved it).
const Outfit& worn_outfit(const ModelSettings& m) {
  return outfit_table(m.clothing).outfits.at(static_cast<size_t>(m.outfit));
}

}  // namespace

// Heat flows from the skin through each layer's resistance (clo) and the surface's to the
// room: the same flux through each, so each resistance takes its share of the drop. A layer
// stands at the temperature at its middle; it passes 10^(-dB / 10) of the power at 94 GHz.
std::vector<LayerSeen> outfit_layers(const PhysicsConfig& pc, const ModelSettings& m) {
  const Outfit& outfit = worn_outfit(m);
  double resistance = kSurfaceResistance;
  for (const Layer& l : outfit.layers) resistance += kGarments[l.garment].clo * kClo;
  const double flux = (pc.skin_temperature - pc.room_temperature) / resistance;  // W / m^2
  std::vector<LayerSeen> out;
  double inner = pc.skin_temperature;  // the layer's inner face
  for (const Layer& l : outfit.layers) {
    const Garment& g = kGarments[l.garment];
    const double drop = flux * g.clo * kClo;
    const double db = kFabrics[l.fabric].db_per_mm * g.thickness_mm;
    out.push_back({std::pow(10.0, -db / 10.0), inner - drop / 2});
    inner -= drop;
  }
  return out;
}

double outfit_surface_share(const ModelSettings& m, bool outer_doubled) {
  const std::vector<Layer>& layers = worn_outfit(m).layers;
  double clothed = 0;
  for (const Layer& l : layers) clothed += kGarments[l.garment].clo * kClo;
  if (outer_doubled && !layers.empty()) clothed += kGarments[layers.back().garment].clo * kClo;
  return kSurfaceResistance / (kSurfaceResistance + clothed);
}

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
  // Folds and seams: over the share m of a pixel where the outer garment lies doubled, what
  // it shows passes the garment once more (t, emitting (1 - t) at its temperature).
  if (vs.model.outfit < 0 || vs.model.clothing_folds == 0) return;
  const std::vector<LayerSeen> layers = outfit_layers(pc, vs.model);
  if (layers.empty()) return;  // bare skin
  const LayerSeen outer = layers.back();
  const Image& folds = vs.assets.folds.at(static_cast<size_t>(vs.scenario.subject)).at(static_cast<size_t>(vs.view));
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const double m = vs.model.clothing_folds * folds.at(x, y) / 255.0, v = f.at(x, y);
      f.at(x, y) = (1 - m) * v + m * (outer.transmission * v + (1 - outer.transmission) * outer.temperature);
    }
}

}  // namespace portalsim::reference
