#include "plan/plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "base/error.h"
#include "plan/knobs.h"
#include "scene/philox.h"

namespace portalsim {

ObjectTransform object_transform(const ModelSettings& m, uint64_t index, int region) {
  ObjectTransform t;
  if (!m.transforms()) return t;
  const Philox4 q = draw(m.seed, index, kStreamTransform, static_cast<uint32_t>(region));
  t.rotation = m.rotate_lo + (m.rotate_hi - m.rotate_lo) * uniform24(q[0]);
  t.scale = m.scale_lo + (m.scale_hi - m.scale_lo) * uniform24(q[1]);
  t.flip = m.flip && (q[2] >> 31) != 0;
  return t;
}

namespace {

// Scenario `index`'s value of the field that drawn element `e` sets (docs/model/drawn-knobs.md):
// the field's own where the element is not drawn; else over [lo, hi] lo + (hi - lo)
// uniform24(word 0) for a real field, lo + below(word 0, hi - lo + 1) for a whole one.
template <class T>
T drawn_value(const ModelSettings& m, T ModelSettings::*field, unsigned e, uint64_t index) {
  const DrawnRange& d = m.drawn[e];
  if (!d.varies()) return m.*field;
  const uint32_t word = draw(m.seed, index, kStreamKnobDraw, e)[0];
  if constexpr (std::is_same_v<T, int>) {
    const int lo = static_cast<int>(d.lo), span = static_cast<int>(d.hi) - lo + 1;
    return lo + static_cast<int>(below(word, static_cast<uint32_t>(span)));
  } else {
    return d.lo + (d.hi - d.lo) * uniform24(word);
  }
}

}  // namespace

int outfit_at(const ModelSettings& m, uint64_t index) {
  if (m.clothing == Clothing::catalogue) return -1;
  const OutfitTable& t = outfit_table(m.clothing);
  const Philox4 q = draw(m.seed, index, kStreamKnobDraw, PS_DRAWN_CLOTHING);
  const uint32_t k = below(q[0], static_cast<uint32_t>(t.class_first.size()));
  return t.class_first[k] + static_cast<int>(below(q[1], static_cast<uint32_t>(t.class_count[k])));
}

const Outfit& outfit_of(const ModelSettings& m, uint64_t index) {
  return outfit_table(m.clothing).outfits.at(static_cast<size_t>(outfit_at(m, index)));
}

std::array<int, 2> raw_grid_at(const ModelSettings& m, uint64_t index) {
  if (!m.raw_grid_drawn()) return {m.raw_width, m.raw_height};
  const uint32_t k =
      below(draw(m.seed, index, kStreamKnobDraw, PS_DRAWN_MMW_RAW)[0], static_cast<uint32_t>(m.raw_grids.size()));
  return m.raw_grids[k];
}

ModelSettings ModelSettings::at_scenario(uint64_t index) const {
  ModelSettings m = *this;
  const std::array<int, 2> raw = raw_grid_at(*this, index);
  m.raw_width = raw[0];
  m.raw_height = raw[1];
  m.raw_grids.clear();
  m.outfit = outfit_at(*this, index);
  for (const DrawnKnob& d : drawn_knobs())
    std::visit(
        [&](auto field) {
          if constexpr (!std::is_same_v<decltype(field), std::monostate>)
            m.*field = drawn_value(*this, field, d.element, index);
        },
        d.field);
  m.drawn = {};
  return m;
}

double drawn_knob_at(const ModelSettings& m, unsigned element, uint64_t index) {
  const auto& field = drawn_knobs().at(element).field;
  if (const auto* real = std::get_if<double ModelSettings::*>(&field)) return drawn_value(m, *real, element, index);
  if (const auto* whole = std::get_if<int ModelSettings::*>(&field)) return drawn_value(m, *whole, element, index);
  throw std::logic_error("drawn element " + std::to_string(element) + " is no number (outfit_at, raw_grid_at)");
}

FeatureLayout FeatureLayout::of(const Catalogue& cat, int block) {
  FeatureLayout f;
  f.block = block;
  f.regions = cat.region_count();
  f.zones = cat.zones;
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& s = cat.sensors[k];
    if (!s.pooled) continue;
    const Sensor& first = cat.sensors[f.pooled.empty() ? k : f.pooled[0]];
    f.uniform = f.uniform && s.width == first.width && s.height == first.height;
    f.grids.push_back({.blocks_x = (s.width + block - 1) / block,
                       .blocks_y = (s.height + block - 1) / block,
                       .offset = f.block_features()});
    f.pooled.push_back(static_cast<int>(k));
    f.view_names.push_back(s.name);
  }
  return f;
}

int FeatureLayout::block_for_grid(const Catalogue& cat, int w, int h) {
  int longest = 0;
  for (const Sensor& s : cat.sensors)
    if (s.pooled) longest = std::max({longest, s.width, s.height});
  for (int block = 1; block <= longest; ++block) {
    bool fits = true;
    for (const Sensor& s : cat.sensors)
      if (s.pooled && ((s.width + block - 1) / block != w || (s.height + block - 1) / block != h)) fits = false;
    if (fits && longest > 0) return block;
  }
  return 0;
}

std::vector<std::string> FeatureLayout::names() const {
  std::vector<std::string> n;
  for (size_t slot = 0; slot < pooled.size(); ++slot)
    for (int by = 0; by < grids[slot].blocks_y; ++by)
      for (int bx = 0; bx < grids[slot].blocks_x; ++bx)
        n.push_back(view_names[slot] + "_r" + std::to_string(by) + "_c" + std::to_string(bx));
  for (int r = 1; r <= regions; ++r) n.push_back("region" + std::to_string(r));
  for (int z = 1; z <= zones; ++z) n.push_back("zone" + std::to_string(z));
  return n;
}

ModelSettings ModelSettings::for_view(const Sensor& s) const {
  ModelSettings m = *this;
  if (s.netd) {
    // Its kind's NETD knob (CameraKind::netd_knob) takes the view's own, never drawn.
    const unsigned knob = camera_kind(s.camera).netd_knob;
    m.*std::get<double ModelSettings::*>(drawn_knobs().at(knob).field) = *s.netd;
    m.drawn[knob] = {};
  }
  if (s.raw) {
    // its own, never drawn
    m.raw_width = (*s.raw)[0];
    m.raw_height = (*s.raw)[1];
    m.raw_grids.clear();
  }
  return m;
}

Fidelity tier_fidelity(Tier t) {
  Fidelity f;
  switch (t) {
    case Tier::exact:
      f.precision = Precision::fp64;
      f.pooling = Pooling::dense;
      break;
    case Tier::standard:
      break;
    case Tier::fast:
      f.precision = Precision::fixed16;
      f.fast_math = true;
      f.noise = NoiseModel::block_mean;
      f.draw = NoiseDraw::irwin_hall;
      break;
  }
  return f;
}

Tier parse_tier(const std::string& name, const std::string& where) {
  if (name == "fast") return Tier::fast;
  if (name == "standard") return Tier::standard;
  if (name == "exact") return Tier::exact;
  throw InputError(where + ": \"" + name + "\" is not a tier (fast, standard, exact)");
}

const char* tier_name(Tier t) { return t == Tier::fast ? "fast" : t == Tier::exact ? "exact" : "standard"; }
const char* precision_name(Precision p) {
  return p == Precision::fp64 ? "fp64" : p == Precision::fixed16 ? "fixed16" : "fp32";
}

void validate(const Plan& plan, const Catalogue& cat) {
  check_knobs(plan);
  if (plan.model.model != Model::physics) return;
  if (plan.metal && !cat.metal_physics.present)
    throw InputError("--model physics: the catalogue " + cat.source +
                     " has no [metal.physics] section (the metal detector's coil model)");
  if (cat.materials.empty())
    throw InputError("--model physics: the catalogue " + cat.source +
                     " has no [[materials]] (emissivities and warming times); add them, as the built-in one has");
  for (const Subject& s : cat.subjects)
    if (s.mmw_level == cat.physics.base_background_gray)
      throw InputError("--model physics: subject " + s.name + "'s mmw_level equals physics.base_background_gray (" +
                       std::to_string(s.mmw_level) + "), so its base image cannot be read as kelvin");
  // A view with a raw grid of its own was checked against its size when the catalogue was read.
  std::vector<std::array<int, 2>> grids = plan.model.raw_grids;
  if (grids.empty()) grids.push_back({plan.model.raw_width, plan.model.raw_height});
  for (const Sensor& s : cat.sensors)
    for (const auto& [w, h] : grids)
      if (camera_kind(s.camera).raw_grid && !s.raw && (w > s.width || h > s.height))
        throw InputError("--mmw-raw: " + std::to_string(w) + "x" + std::to_string(h) + " is finer than the " + s.name +
                         " view (" + std::to_string(s.width) + "x" + std::to_string(s.height) + ")");
}

}  // namespace portalsim
