#include "backend/opencl/physics_params.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <stdexcept>

#include "backend/opencl/gauss_table.h"
#include "plan/knobs.h"
#include "shared.h"

namespace portalsim::opencl {

namespace {

// An object's physical temperature after `worn` minutes on the body: from the room towards
// the skin with its material's time constant.
double worn_temperature(const PhysicsConfig& pc, const Material& mat, double worn) {
  return pc.skin_temperature - (pc.skin_temperature - pc.room_temperature) * std::exp(-worn / mat.warm_minutes);
}

// A Gaussian of `sigma` taps over +-4 sigma, normalised; sigma 0 is the single tap 1.
void append_gaussian_taps(std::vector<double>& p, double sigma, int32_t& radius) {
  radius = sigma > 0 ? static_cast<int32_t>(std::ceil(4.0 * sigma)) : 0;
  double total = 0;
  const size_t first = p.size();
  for (int d = -radius; d <= radius; ++d) {
    p.push_back(sigma > 0 ? std::exp(-0.5 * d * d / (sigma * sigma)) : 1.0);
    total += p.back();
  }
  for (size_t k = first; k < p.size(); ++k) p[k] /= total;
}

// The raw grid's weight of each view pixel along one axis (size pixels, raw cells): the
// PSF's taps (edges held) folded into each cell's box over size / raw pixels; then the
// first and last cell each pixel reaches.
void axis_weights(int size, int raw, const double* taps, int radius, std::vector<double>& w,
                  std::vector<double>& band) {
  w.assign(static_cast<size_t>(raw) * size, 0.0);
  const double step = double(size) / raw;
  for (int c = 0; c < raw; ++c)
    for (int x = static_cast<int>(std::floor(c * step)); x < std::min(size, int(std::ceil((c + 1) * step))); ++x) {
      const double share = (std::min(x + 1.0, (c + 1) * step) - std::max(double(x), c * step)) / step;
      for (int d = -radius; d <= radius; ++d)
        w[size_t(c) * size + std::clamp(x + d, 0, size - 1)] += share * taps[d + radius];
    }
  band.assign(2 * static_cast<size_t>(size), 0.0);
  for (int x = 0; x < size; ++x) {
    int lo = raw, hi = -1;
    for (int c = 0; c < raw; ++c)
      if (w[size_t(c) * size + x] != 0) lo = std::min(lo, c), hi = std::max(hi, c);
    band[2 * x] = lo;
    band[2 * x + 1] = hi;
  }
}

// An outfit's physics as the tables take it: its MMW transmission tc and emission E at 94
// GHz (what reaches the camera of a surface's X is tc X + E), and the fraction g of the skin's
// excess over the room that reaches its surface (IR). Layer k, innermost first, passes
// t_k = 10^(-dB/10) and emits (1 - t_k) T_k at the temperature halfway through it along the
// chain of resistances skin -> layers -> room (docs/model/clothing.md).
// Where the outer garment lies doubled (its folds and seams), a value v turns into
// T + (1 + k)(v - T): in MMW the garment passes t_outer of v - T_outer again (k = t_outer - 1,
// T = T_outer); in IR the surface keeps g' / g of its excess over the room (T the room), g' the
// share with the outer garment's resistance counted twice.
struct OutfitPhysics {
  double tc = 1, emission = 0, surface = 1;
  double mmw_fold_k = 0, mmw_fold_t = 0, ir_fold_k = 0;
};
OutfitPhysics outfit_physics(const PhysicsConfig& pc, const Outfit& o) {
  const double total = kSurfaceResistance + o.clo() * kClo;
  OutfitPhysics r;
  double inside = 0;
  for (const Layer& l : o.layers) {
    const Garment& g = kGarments[l.garment];
    const double t = std::pow(10.0, -kFabrics[l.fabric].db_per_mm * g.thickness_mm / 10.0);
    const double R = g.clo * kClo;
    const double temperature =
        pc.skin_temperature - (pc.skin_temperature - pc.room_temperature) * (inside + R / 2) / total;
    inside += R;
    r.emission = t * r.emission + (1 - t) * temperature;
    r.tc *= t;
    r.mmw_fold_k = t - 1;
    r.mmw_fold_t = temperature;
  }
  r.surface = kSurfaceResistance / total;
  if (!o.layers.empty()) {
    const double outer = kGarments[o.layers.back().garment].clo * kClo;
    r.ir_fold_k = -outer / (total + outer);
  }
  return r;
}

// Appends v to the parameters; its offset.
int32_t append(std::vector<double>& p, const std::vector<double>& v) {
  if (p.size() + v.size() > 0x7fffffffu) throw std::runtime_error("physics tables exceed 2^31 values");
  const auto at = static_cast<int32_t>(p.size());
  p.insert(p.end(), v.begin(), v.end());
  return at;
}

// What the steps below read: the view's catalogue, its knobs and its camera kind.
struct Derive {
  const Catalogue& cat;
  const PhysicsConfig& pc;
  const ModelSettings& m;
  bool ir;  // the IR surface model's formulas (its kind's FillStep::surface)
};

// The MMW camera's scalars; scene and clothing are set once their blocks are placed.
PsPhysMmw mmw_scalars(const Plan& plan, const ModelSettings& m) {
  PsPhysMmw h{};
  h.common.window_min = m.window_lo;
  h.common.window_max = m.window_hi;
  // The NETD over the frames where neither is drawn (mmw_noise_of).
  const MmwNoise noise = mmw_noise(plan, m);
  h.netd = noise.netd_lo;
  h.frames_as_one = noise.as_one;
  return h;
}

// The IR camera's scalars, likewise.
PsPhysIr ir_scalars(const PhysicsConfig& pc) {
  PsPhysIr h{};
  h.common.window_min = pc.ir_display_min;
  h.common.window_max = pc.ir_display_max;
  return h;
}

// Writes a kind's scalars at the parameters' start (PS_PARAM each: the layout's every field
// is a double on the host, so params() converting each keeps every field's index), and the
// view's drawn ranges from the knobs' declarations (PsPhys::drawn: every kind begins with PsPhys).
template <class Scalars>
void put_scalars(std::vector<double>& p, const Scalars& h, const ModelSettings& m) {
  static_assert(sizeof(Scalars) % sizeof(double) == 0 && sizeof(Scalars) <= sizeof(PsPhysKinds));
  std::memcpy(p.data(), &h, sizeof h);
  const PsDrawn drawn = drawn_ranges(m);
  std::memcpy(p.data() + offsetof(PsPhys, drawn) / sizeof(double), &drawn, sizeof drawn);
}

// Per subject, its base image's value to kelvin: the IR index map (under an outfit, its
// surface's share g of the excess over the room), or the MMW's gray between the room behind
// and the bare body under the clothing. Per variant: the IR surface's contact shadow, or the
// MMW apparent temperature. `seen_as` is the clothing's (e, T) -> apparent temperature.
template <class Seen>
void append_head(std::vector<double>& out, const Derive& d, const Seen& seen_as, double g) {
  const PhysicsConfig& pc = d.pc;
  for (const Subject& subj : d.cat.subjects) {
    const double body = seen_as(pc.skin_emissivity_of(subj), pc.skin_temperature_of(subj));
    const double gain = d.ir ? (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0
                             : (body - pc.background_temperature) / (subj.mmw_level - pc.base_background_gray);
    const double offset = d.ir ? pc.ir_index_min_k : pc.background_temperature - gain * pc.base_background_gray;
    out.push_back(g * gain);
    out.push_back(g * offset + (1 - g) * (d.ir ? pc.room_temperature : 0.0));
  }
  for (size_t v = 0; v < d.cat.variant_list.size(); ++v) {
    const Material& mat = d.cat.materials.at(d.cat.object_of(static_cast<int>(v)).material_id);
    const double worn = worn_temperature(pc, mat, d.m.worn_minutes);
    out.push_back(d.ir ? -pc.ir_coupling * (pc.skin_temperature - worn) : seen_as(mat.emissivity, worn));
  }
}

// The PSF's sigma in the view's pixels. MMW: the Airy core's FWHM, 1.02 lambda / D at the
// range, as a Gaussian of that FWHM. IR: ir_spread_mm over the view's pixel (as wide as an
// MMW view).
double psf_sigma(const PhysicsConfig& pc, const Sensor& s, bool ir) {
  const double span_m = 2.0 * pc.range_m * std::tan(pc.fov_rad / 2.0);
  const double lambda = 299792458.0 / (pc.frequency_ghz * 1e9);
  return ir ? pc.ir_spread_mm / (1000.0 * span_m / s.width)
            : 1.02 * lambda / pc.aperture_m * pc.range_m / (span_m / s.width) / 2.3548200450309493;
}

bool scene_drawn(const ModelSettings& m) {
  return m.drawn[PS_DRAWN_ILLUMINATION].varies() || m.drawn[PS_DRAWN_WORN_MINUTES].varies();
}

// The moves of each subject and variant under clothing of MMW transmission tc, linearly in
// the illumination and in each material's exp(-worn / tau).
void append_moves(std::vector<double>& out, const Derive& d, double tc) {
  const PhysicsConfig& pc = d.pc;
  const DrawnRange& ill = d.m.drawn[PS_DRAWN_ILLUMINATION];
  const double ill_span = ill.varies() ? ill.hi - ill.lo : 0.0;
  // The bare body's apparent temperature moves by tc (1 - e_skin) per kelvin of illumination.
  for (const Subject& subj : d.cat.subjects) {
    const double body_span = d.ir ? 0.0 : tc * (1 - pc.skin_emissivity_of(subj)) * ill_span;
    const double dgain = d.ir ? 0.0 : body_span / (subj.mmw_level - pc.base_background_gray);
    out.push_back(dgain);
    out.push_back(-dgain * pc.base_background_gray);
  }
  for (size_t v = 0; v < d.cat.variant_list.size(); ++v) {
    const Material& mat = d.cat.materials.at(d.cat.object_of(static_cast<int>(v)).material_id);
    // worn = skin - (skin - room) exp(-worn / tau): the IR shadow (against skin or room)
    // moves by -coupling (skin - room) per unit of it, the MMW value by -tc e (skin - room).
    const double per_decay = d.ir ? -pc.ir_coupling * (pc.skin_temperature - pc.room_temperature)
                                  : -tc * mat.emissivity * (pc.skin_temperature - pc.room_temperature);
    out.push_back(d.ir ? 0.0 : tc * (1 - mat.emissivity) * ill_span);
    out.push_back(per_decay);
    out.push_back(1.0 / mat.warm_minutes);
    out.push_back(std::exp(-d.m.worn_minutes / mat.warm_minutes));
  }
}

// Where the illumination or the worn time is drawn per scenario, the scene block
// (PsPhys::scene) but its MMW grids: the values above hold at the ranges' low ends, and each
// scenario's moves from them. Empty where neither is drawn.
std::vector<double> scene_block(const Derive& d) {
  if (!scene_drawn(d.m)) return {};
  const DrawnRange& ill = d.m.drawn[PS_DRAWN_ILLUMINATION];
  std::vector<double> scene = {ill.varies() ? 1.0 : 0.0};
  append_moves(scene, d, d.pc.clothing_transmission);
  return scene;
}

// Where the clothing is drawn per scenario, the clothing block (PsPhys::clothing) but its MMW
// grids: each outfit's entries as above, under its layers instead of the catalogue's
// clothing. Empty where the clothing is the catalogue's.
std::vector<double> clothing_block(const Derive& d, const AssetSet& assets) {
  const OutfitTable& outfits = outfit_table(d.m.clothing);
  if (outfits.outfits.empty()) return {};
  const PhysicsConfig& pc = d.pc;
  const bool scene = scene_drawn(d.m);
  const size_t C = outfits.class_first.size(), S = d.cat.subjects.size(), V = d.cat.variant_list.size();
  const size_t stride = PS_OUTFIT_HEAD + 2 * S + V + (scene ? 2 * S + 4 * V : 0);
  // The kernels read each view's fold pattern from the atlas (fold_row).
  if (d.m.has_folds() && assets.folds.empty())
    throw std::logic_error("--clothing-folds: the assets were built without fold patterns");
  std::vector<double> clothing = {double(C), double(stride), 0.0, 0.0};
  for (int f : outfits.class_first) clothing.push_back(f);
  for (int n : outfits.class_count) clothing.push_back(n);
  for (const Outfit& o : outfits.outfits) {
    const OutfitPhysics op = outfit_physics(pc, o);
    clothing.push_back(d.ir ? op.surface / pc.ir_coupling : 1.0);
    clothing.push_back(double(PS_OUTFIT_HEAD + 2 * S + V));
    clothing.push_back(d.ir ? op.ir_fold_k : op.mmw_fold_k);
    clothing.push_back(d.ir ? pc.room_temperature : op.mmw_fold_t);
    append_head(
        clothing, d, [&](double e, double t) { return op.tc * (e * t + (1 - e) * d.m.illumination) + op.emission; },
        d.ir ? op.surface : 1.0);
    if (scene) append_moves(clothing, d, op.tc);
  }
  return clothing;
}

// The IR contact shadow's off-body block (PsPhysTables::off_body): where an object reaches
// past the body's outline, its shadow is taken against the room it touches there, not the skin.
std::vector<double> off_body_block(const Derive& d) {
  const PhysicsConfig& pc = d.pc;
  std::vector<double> off_body;
  for (size_t subj = 0; subj < d.cat.subjects.size(); ++subj) off_body.push_back(pc.ir_body_index());
  // Each variant's shadow against the room.
  for (size_t v = 0; v < d.cat.variant_list.size(); ++v) {
    const Material& mat = d.cat.materials.at(d.cat.object_of(static_cast<int>(v)).material_id);
    off_body.push_back(-pc.ir_coupling * (pc.room_temperature - worn_temperature(pc, mat, d.m.worn_minutes)));
  }
  // Each subject's shadows scale with its skin above the room: every shadow above is
  // -coupling (skin - room) times a factor of the material and the worn time.
  const double span = pc.skin_temperature - pc.room_temperature;
  for (const Subject& subj : d.cat.subjects) {
    off_body.push_back(span == 0 ? 1.0 : (pc.skin_temperature_of(subj) - pc.room_temperature) / span);
  }
  return off_body;
}

// The MMW raw-grid path's tables (kernels/physics_raw.cl) appended to t, with the scene and
// clothing blocks' grids; sets where the blocks lie in `common`.
void append_mmw_grids(PhysicsTables& t, const Derive& d, const AssetSet& assets, const Sensor& s, int view,
                      const std::vector<double>& psf, std::vector<double>& scene, std::vector<double>& clothing,
                      PsPhys& common) {
  std::vector<double>& p = t.values;
  const int W = s.width, H = s.height, RW = d.m.raw_width, RH = d.m.raw_height;
  const size_t S = d.cat.subjects.size();
  std::vector<double> wx, wy, cband, rband;
  axis_weights(W, RW, psf.data(), t.at.psf_radius, wx, cband);
  axis_weights(H, RH, psf.data(), t.at.psf_radius, wy, rband);
  t.at.wx = append(p, wx);
  t.at.wy = append(p, wy);
  t.at.cband = append(p, cband);
  t.at.rband = append(p, rband);
  t.at.display = append_display_tables(p, d.m, W, H, RW, RH);
  // Each subject's grid of a value per view pixel, wy . T . wx^T, T = value(subject, x, y).
  const auto grids_of = [&](const auto& value) {
    std::vector<double> bare(S * size_t(RW) * RH, 0.0), rows(size_t(H) * RW);
    for (size_t subj = 0; subj < S; ++subj) {
      std::fill(rows.begin(), rows.end(), 0.0);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const double kelvin = value(subj, x, y);
          for (int c = int(cband[2 * x]); c <= int(cband[2 * x + 1]); ++c)
            rows[size_t(y) * RW + c] += wx[size_t(c) * W + x] * kelvin;
        }
      double* out = &bare[subj * size_t(RW) * RH];
      for (int y = 0; y < H; ++y)
        for (int r = int(rband[2 * y]); r <= int(rband[2 * y + 1]); ++r)
          for (int c = 0; c < RW; ++c) out[size_t(r) * RW + c] += wy[size_t(r) * H + y] * rows[size_t(y) * RW + c];
    }
    return bare;
  };
  // Each subject's bare raw grid: its base image in kelvin at the subject's (gain, offset);
  // with the scene block, also its change over the illumination's range, the same sums at the
  // change of (gain, offset).
  const auto bare_grids = [&](const double* gains) {
    return grids_of([&](size_t subj, int x, int y) {
      return gains[2 * subj] * assets.bases[subj][view].at(x, y) + gains[2 * subj + 1];
    });
  };
  t.at.base = append(p, bare_grids(&p[PS_PHYS_SUBJECTS]));
  if (!scene.empty()) {
    const std::vector<double> moved = bare_grids(&scene[PS_SCENE_SUBJECTS]);
    scene.insert(scene.end(), moved.begin(), moved.end());
    common.scene = append(p, scene);
  }
  if (clothing.empty()) return;
  // The gray grids: each subject's bare grid at (gain, offset) (1, 0).
  std::vector<double> unit(2 * S, 0.0);
  for (size_t k = 0; k < S; ++k) unit[2 * k] = 1;
  clothing[PS_CLOTHING_GRIDS] = append(p, bare_grids(unit.data()));
  // The fold grids: each subject's fold share m (0 .. 1) times its gray, then m alone.
  if (d.m.has_folds()) {
    std::vector<double> folds = grids_of([&](size_t subj, int x, int y) {
      return assets.folds[subj][view].at(x, y) / 255.0 * assets.bases[subj][view].at(x, y);
    });
    const std::vector<double> share =
        grids_of([&](size_t subj, int x, int y) { return assets.folds[subj][view].at(x, y) / 255.0; });
    folds.insert(folds.end(), share.begin(), share.end());
    clothing[PS_CLOTHING_FOLD_GRIDS] = append(p, folds);
  }
  common.clothing = append(p, clothing);
}

// What a kind's fill step takes: the tables so far (the head, the PSF's taps and the
// Gaussians) and the scene and clothing blocks, which it places.
struct FillArgs {
  PhysicsTables& t;
  const Derive& d;
  const AssetSet& assets;
  const Plan& plan;
  const Sensor& s;
  int view;
  const std::vector<double>& psf;
  std::vector<double>&scene, &clothing;
};

// The IR surface model: the off-body shadows and PsPhysIr.
void fill_ir_surface(const FillArgs& a) {
  std::vector<double>& p = a.t.values;
  PsPhysIr h = ir_scalars(a.d.pc);
  a.t.at.off_body = append(p, off_body_block(a.d));
  if (!a.scene.empty()) h.common.scene = append(p, a.scene);
  if (!a.clothing.empty()) h.common.clothing = append(p, a.clothing);
  put_scalars(p, h, a.d.m);
}

// The MMW radiometry on a raw grid: the grid's tables and PsPhysMmw.
void fill_mmw_raw_grid(const FillArgs& a) {
  PsPhysMmw h = mmw_scalars(a.plan, a.d.m);
  append_mmw_grids(a.t, a.d, a.assets, a.s, a.view, a.psf, a.scene, a.clothing, h.common);
  put_scalars(a.t.values, h, a.d.m);
}

// The fill steps a camera kind may name (CameraKind::physics_fill). `surface`: the shared
// steps above take the IR surface model's formulas (the index map, the contact shadow, the
// surface under clothing), else the MMW radiometry's.
struct FillStep {
  const char* name;
  bool surface;
  void (*fill)(const FillArgs&);
};
constexpr FillStep kFillSteps[] = {
    {"mmw_raw_grid", false, fill_mmw_raw_grid},
    {"ir_surface", true, fill_ir_surface},
};

const FillStep& fill_step(const Sensor& s) {
  const char* name = camera_kind(s.camera).physics_fill;
  for (const FillStep& f : kFillSteps)
    if (std::strcmp(f.name, name) == 0) return f;
  throw std::logic_error(std::string("camera kind ") + camera_name(s.camera) + ": no physics fill step " + name);
}

}  // namespace

bool has_physics_fill(const CameraKind& kind) {
  for (const FillStep& f : kFillSteps)
    if (std::strcmp(f.name, kind.physics_fill) == 0) return true;
  return false;
}

size_t mmw_display_scratch(const Sensor& s, int raw_width, int raw_height) {
  return PS_MMW_DISPLAY_SCRATCH(s.width, s.height, raw_width, raw_height);
}

PhysicsTables physics_tables(const Catalogue& cat, const AssetSet& assets, const Plan& plan, const ModelSettings& m,
                             int view) {
  const Sensor& s = cat.sensors[view];
  const FillStep& step = fill_step(s);
  const Derive d{cat, cat.physics, m, step.surface};
  PhysicsTables t;
  std::vector<double>& p = t.values;
  p.assign(PS_PHYS_SUBJECTS, 0.0);
  append_head(
      p, d, [&](double e, double k) { return d.pc.seen_through_clothing(e, k, m.illumination); }, 1.0);
  const size_t taps = p.size();
  append_gaussian_taps(p, psf_sigma(d.pc, s, d.ir), t.at.psf_radius);
  const std::vector<double> psf(p.begin() + static_cast<std::ptrdiff_t>(taps), p.end());
  t.at.gauss = append(p, gauss_table());  // the sensor noise's table Gaussians
  std::vector<double> scene = scene_block(d), clothing = clothing_block(d, assets);
  step.fill({t, d, assets, plan, s, view, psf, scene, clothing});
  return t;
}

std::vector<double> drawn_params(const ModelSettings& m) {
  std::vector<double> p(PS_PHYS_SUBJECTS, 0.0);
  put_scalars(p, PsPhys{}, m);
  return p;
}

}  // namespace portalsim::opencl
