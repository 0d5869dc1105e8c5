#include "plan/plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

// Element e's draw over [lo, hi] (docs/model/drawn-knobs.md): lo + (hi - lo) uniform24(word 0)
// for a real knob, lo + below(word 0, hi - lo + 1) for a whole one.
double drawn_real(const ModelSettings& m, unsigned e, uint64_t index) {
  const DrawnRange& d = m.drawn[e];
  return d.lo + (d.hi - d.lo) * uniform24(draw(m.seed, index, kStreamKnobDraw, e)[0]);
}

int drawn_whole(const ModelSettings& m, unsigned e, uint64_t index) {
  const int lo = static_cast<int>(m.drawn[e].lo), span = static_cast<int>(m.drawn[e].hi) - lo + 1;
  return lo + static_cast<int>(below(draw(m.seed, index, kStreamKnobDraw, e)[0], static_cast<uint32_t>(span)));
}

}  // namespace

int metal_noise_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_METAL_NOISE].varies() ? drawn_whole(m, PS_DRAWN_METAL_NOISE, index) : m.metal_noise;
}

double ir_netd_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_IR_NETD].varies() ? drawn_real(m, PS_DRAWN_IR_NETD, index) : m.ir_netd;
}

double netd_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_NETD].varies() ? drawn_real(m, PS_DRAWN_NETD, index) : m.netd;
}

int frames_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_FRAMES].varies() ? drawn_whole(m, PS_DRAWN_FRAMES, index) : m.frames;
}

double illumination_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_ILLUMINATION].varies() ? drawn_real(m, PS_DRAWN_ILLUMINATION, index) : m.illumination;
}

double pixel_noise_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_PIXEL_NOISE].varies() ? drawn_real(m, PS_DRAWN_PIXEL_NOISE, index) : m.pixel_sigma;
}

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

double window_lo_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_WINDOW_LO].varies() ? drawn_real(m, PS_DRAWN_WINDOW_LO, index) : m.window_lo;
}

double window_hi_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_WINDOW_HI].varies() ? drawn_real(m, PS_DRAWN_WINDOW_HI, index) : m.window_hi;
}

double worn_minutes_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_WORN_MINUTES].varies() ? drawn_real(m, PS_DRAWN_WORN_MINUTES, index) : m.worn_minutes;
}

double clothing_folds_at(const ModelSettings& m, uint64_t index) {
  return m.drawn[PS_DRAWN_CLOTHING_FOLDS].varies() ? drawn_real(m, PS_DRAWN_CLOTHING_FOLDS, index) : m.clothing_folds;
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
  m.metal_noise = metal_noise_at(*this, index);
  m.pixel_sigma = pixel_noise_at(*this, index);
  m.ir_netd = ir_netd_at(*this, index);
  m.netd = netd_at(*this, index);
  m.frames = frames_at(*this, index);
  m.illumination = illumination_at(*this, index);
  m.worn_minutes = worn_minutes_at(*this, index);
  m.window_lo = window_lo_at(*this, index);
  m.window_hi = window_hi_at(*this, index);
  m.outfit = outfit_at(*this, index);
  m.clothing_folds = clothing_folds_at(*this, index);
  m.drawn = {};
  return m;
}

double drawn_knob_at(const ModelSettings& m, unsigned element, uint64_t index) {
  switch (element) {
    case PS_DRAWN_METAL_NOISE:
      return metal_noise_at(m, index);
    case PS_DRAWN_IR_NETD:
      return ir_netd_at(m, index);
    case PS_DRAWN_PIXEL_NOISE:
      return pixel_noise_at(m, index);
    case PS_DRAWN_NETD:
      return netd_at(m, index);
    case PS_DRAWN_FRAMES:
      return frames_at(m, index);
    case PS_DRAWN_ILLUMINATION:
      return illumination_at(m, index);
    case PS_DRAWN_WORN_MINUTES:
      return worn_minutes_at(m, index);
    case PS_DRAWN_WINDOW_LO:
      return window_lo_at(m, index);
    case PS_DRAWN_WINDOW_HI:
      return window_hi_at(m, index);
    case PS_DRAWN_CLOTHING_FOLDS:
      return clothing_folds_at(m, index);
  }
  throw std::logic_error("no drawn knob " + std::to_string(element));
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
  if (s.netd) (s.camera == Camera::ir ? m.ir_netd : m.netd) = *s.netd;
  if (s.netd) m.drawn[s.camera == Camera::ir ? PS_DRAWN_IR_NETD : PS_DRAWN_NETD] = {};  // its own, never drawn
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
      if (s.camera == Camera::mmw && !s.raw && (w > s.width || h > s.height))
        throw InputError("--mmw-raw: " + std::to_string(w) + "x" + std::to_string(h) + " is finer than the " + s.name +
                         " view (" + std::to_string(s.width) + "x" + std::to_string(s.height) + ")");
}

}  // namespace portalsim
