#include "backend/opencl/physics_params.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "backend/opencl/gauss_table.h"
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

}  // namespace

size_t mmw_display_scratch(const Sensor& s, int raw_width, int raw_height) {
  return PS_MMW_DISPLAY_SCRATCH(s.width, s.height, raw_width, raw_height);
}

PhysicsTables physics_tables(const Catalogue& cat, const AssetSet& assets, const Plan& plan, const ModelSettings& m,
                             int view) {
  const Sensor& s = cat.sensors[view];
  const PhysicsConfig& pc = cat.physics;
  const bool ir = s.camera == Camera::ir;
  const auto seen = [&](double e, double t) { return pc.seen_through_clothing(e, t, m.illumination); };
  PhysicsTables t;
  std::vector<double>& p = t.values;
  p.assign(PS_PHYS_SUBJECTS, 0.0);
  p[PS_PHYS_BACKGROUND] = pc.background_temperature;
  p[PS_PHYS_WINDOW_MIN] = ir ? pc.ir_display_min : m.window_lo;
  p[PS_PHYS_WINDOW_MAX] = ir ? pc.ir_display_max : m.window_hi;
  // The view's NETD, and its range and the frames' where drawn per scenario (mmw_noise_of,
  // ir_netd_of).
  if (ir) {
    const DrawnRange& drawn_ir_netd = m.drawn[PS_DRAWN_IR_NETD];
    p[PS_PHYS_NETD] = m.ir_netd;
    p[PS_PHYS_NETD_HI] = drawn_ir_netd.varies() ? drawn_ir_netd.hi : m.ir_netd;
    p[PS_PHYS_FRAMES_LO] = p[PS_PHYS_FRAMES_HI] = 1;
  } else {
    const MmwNoise noise = mmw_noise(plan, m);
    p[PS_PHYS_NETD] = noise.netd_lo;
    p[PS_PHYS_NETD_HI] = noise.netd_hi;
    p[PS_PHYS_FRAMES_LO] = noise.frames_lo;
    p[PS_PHYS_FRAMES_HI] = noise.frames_hi;
    p[PS_PHYS_FRAMES_AS_ONE] = noise.as_one;
  }
  // Per subject, its base image's value to kelvin: the IR index map, or the MMW's gray
  // between the room behind and the bare body.
  for (const Subject& subj : cat.subjects) {
    const double body = seen(pc.skin_emissivity_of(subj), pc.skin_temperature_of(subj));
    const double gain = ir ? (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0
                           : (body - pc.background_temperature) / (subj.mmw_level - pc.base_background_gray);
    p.push_back(gain);
    p.push_back(ir ? pc.ir_index_min_k : pc.background_temperature - gain * pc.base_background_gray);
  }
  // Per variant: the IR surface's contact shadow (and, for phys_off_body, the same against
  // the room), or the MMW apparent temperature.
  std::vector<double> off_body_shadow;
  for (size_t v = 0; v < cat.variant_list.size(); ++v) {
    const Material& mat = cat.materials.at(cat.object_of(static_cast<int>(v)).material_id);
    const double worn = worn_temperature(pc, mat, m.worn_minutes);
    p.push_back(ir ? -pc.ir_coupling * (pc.skin_temperature - worn) : seen(mat.emissivity, worn));
    if (ir) off_body_shadow.push_back(-pc.ir_coupling * (pc.room_temperature - worn));
  }
  // MMW: the Airy core's FWHM, 1.02 lambda / D at the range, in this view's pixels, as a
  // Gaussian of that FWHM. IR: ir_spread_mm over the view's pixel (as wide as an MMW view).
  const double span_m = 2.0 * pc.range_m * std::tan(pc.fov_rad / 2.0);
  const double lambda = 299792458.0 / (pc.frequency_ghz * 1e9);
  const double sigma = ir ? pc.ir_spread_mm / (1000.0 * span_m / s.width)
                          : 1.02 * lambda / pc.aperture_m * pc.range_m / (span_m / s.width) / 2.3548200450309493;
  const size_t taps = p.size();
  append_gaussian_taps(p, sigma, t.radius);
  const std::vector<double> psf(p.begin() + static_cast<std::ptrdiff_t>(taps), p.end());
  const auto append = [&](const std::vector<double>& v) {
    if (p.size() + v.size() > 0x7fffffffu) throw std::runtime_error("physics tables exceed 2^31 values");
    const int32_t at = static_cast<int32_t>(p.size());
    p.insert(p.end(), v.begin(), v.end());
    return at;
  };
  t.gauss = append(gauss_table());  // the sensor noise's table Gaussians
  // Where the illumination or the worn time is drawn per scenario, the scene block
  // (PS_PHYS_SCENE): the values above hold at the ranges' low ends, and each scenario's
  // moves from them, linearly in the illumination and in each material's exp(-worn / tau).
  const DrawnRange &ill = m.drawn[PS_DRAWN_ILLUMINATION], &worn = m.drawn[PS_DRAWN_WORN_MINUTES];
  const bool scene_drawn = ill.varies() || worn.varies();
  const double ill_span = ill.varies() ? ill.hi - ill.lo : 0.0;
  std::vector<double> scene;
  if (scene_drawn) {
    scene = {ill.varies() ? 1.0 : 0.0, m.worn_minutes, worn.varies() ? worn.hi : m.worn_minutes};
    // The bare body's apparent temperature moves by tc (1 - e_skin) per kelvin of illumination.
    for (const Subject& subj : cat.subjects) {
      const double body_span = ir ? 0.0 : pc.clothing_transmission * (1 - pc.skin_emissivity_of(subj)) * ill_span;
      const double dgain = ir ? 0.0 : body_span / (subj.mmw_level - pc.base_background_gray);
      scene.push_back(dgain);
      scene.push_back(-dgain * pc.base_background_gray);
    }
    for (size_t v = 0; v < cat.variant_list.size(); ++v) {
      const Material& mat = cat.materials.at(cat.object_of(static_cast<int>(v)).material_id);
      // worn = skin - (skin - room) exp(-worn / tau): the IR shadow (against skin or room)
      // moves by -coupling (skin - room) per unit of it, the MMW value by -tc e (skin - room).
      const double per_decay =
          ir ? -pc.ir_coupling * (pc.skin_temperature - pc.room_temperature)
             : -pc.clothing_transmission * mat.emissivity * (pc.skin_temperature - pc.room_temperature);
      scene.push_back(ir ? 0.0 : pc.clothing_transmission * (1 - mat.emissivity) * ill_span);
      scene.push_back(per_decay);
      scene.push_back(1.0 / mat.warm_minutes);
      scene.push_back(std::exp(-m.worn_minutes / mat.warm_minutes));
    }
  }
  if (ir) {
    // Where an object reaches past the body's outline, its shadow is taken against the room
    // it touches there, not the skin (PsViewLaunch::phys_off_body).
    std::vector<double> off_body;
    const double per_index = (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0;
    const double body_from = (pc.room_temperature + pc.skin_temperature) / 2;
    for (size_t subj = 0; subj < cat.subjects.size(); ++subj)
      off_body.push_back(std::ceil((body_from - pc.ir_index_min_k) / per_index));
    off_body.insert(off_body.end(), off_body_shadow.begin(), off_body_shadow.end());
    // Each subject's shadows scale with its skin above the room: every shadow above is
    // -coupling (skin - room) times a factor of the material and the worn time.
    const double span = pc.skin_temperature - pc.room_temperature;
    for (const Subject& subj : cat.subjects) {
      off_body.push_back(span == 0 ? 1.0 : (pc.skin_temperature_of(subj) - pc.room_temperature) / span);
    }
    t.off_body = append(off_body);
    if (scene_drawn) p[PS_PHYS_SCENE] = append(scene);
    return t;
  }
  // The MMW raw-grid path's tables (kernels/physics_raw.cl).
  const int W = s.width, H = s.height, RW = m.raw_width, RH = m.raw_height;
  std::vector<double> wx, wy, cband, rband;
  axis_weights(W, RW, psf.data(), t.radius, wx, cband);
  axis_weights(H, RH, psf.data(), t.radius, wy, rband);
  t.wx = append(wx);
  t.wy = append(wy);
  t.cband = append(cband);
  t.rband = append(rband);
  t.display = append_display_tables(p, m, W, H, RW, RH);
  // Each subject's bare raw grid: wy . T . wx^T over its base image in kelvin at the
  // subject's (gain, offset); with the scene block, also its change over the illumination's
  // range, the same sums at the change of (gain, offset).
  const auto bare_grids = [&](const double* gains) {
    std::vector<double> bare(cat.subjects.size() * size_t(RW) * RH, 0.0), rows(size_t(H) * RW);
    for (size_t subj = 0; subj < cat.subjects.size(); ++subj) {
      const Image& base = assets.bases[subj][view];
      const double gain = gains[2 * subj], offset = gains[2 * subj + 1];
      std::fill(rows.begin(), rows.end(), 0.0);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const double kelvin = gain * base.at(x, y) + offset;
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
  t.base = append(bare_grids(&p[PS_PHYS_SUBJECTS]));
  if (scene_drawn) {
    const std::vector<double> moved = bare_grids(&scene[PS_SCENE_SUBJECTS]);
    scene.insert(scene.end(), moved.begin(), moved.end());
    p[PS_PHYS_SCENE] = append(scene);
  }
  return t;
}

}  // namespace portalsim::opencl
