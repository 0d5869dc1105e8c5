#include "backend/opencl/view_derive.h"

#include <algorithm>
#include <cstring>

#include "backend/opencl/buffers.h"
#include "backend/opencl/display_tables.h"
#include "backend/opencl/physics_params.h"
#include "backend/opencl/table_key.h"

namespace portalsim::opencl {

namespace {

// A run takes at most two derivations per view (its plan's, and for the physics
// features-only path the noise-free plan's); twice that lets a long-lived serve switch
// between two settings without deriving again, and bounds what trying knob after knob keeps.
size_t capacity_for(const Catalogue& cat) { return 4 * std::max<size_t>(cat.sensors.size(), 1); }

PsViewLaunch settings(const Catalogue& cat, const Plan& plan, const ModelSettings& m, int view) {
  const Sensor& s = cat.sensors[view];
  PsViewLaunch L{};
  L.view = view;
  L.views = static_cast<int32_t>(cat.sensors.size());
  L.sprite_set = s.sprite_set;
  L.variants = static_cast<int32_t>(cat.variant_list.size());
  L.region_mask = s.region_mask;
  L.width = s.width;
  L.height = s.height;
  L.patterns = static_cast<int32_t>(cat.noise.size());
  L.tile_size = cat.images.noise_size;
  L.flags = (s.pattern_noise && m.pattern_noise ? PS_FLAG_PATTERN_NOISE : 0) |
            (plan.pixel_noise_per_pixel() ? PS_FLAG_PIXEL_NOISE : 0) | (m.bilinear ? PS_FLAG_BILINEAR : 0) |
            (m.transforms() ? PS_FLAG_AFFINE : 0) | (m.flip ? PS_FLAG_FLIP : 0) |
            (plan.physics_draws_approximated() ? PS_FLAG_FAST_DRAWS : 0);
  L.jitter_x = static_cast<float>(m.jitter * s.jitter_scale_x);
  L.jitter_y = static_cast<float>(m.jitter * s.jitter_scale_y);
  L.rotate_lo = static_cast<float>(m.rotate_lo);
  L.rotate_hi = static_cast<float>(m.rotate_hi);
  L.scale_lo = static_cast<float>(m.scale_lo);
  L.scale_hi = static_cast<float>(m.scale_hi);
  const double ranges[4] = {m.rotate_lo, m.rotate_hi, m.scale_lo, m.scale_hi};
  std::memcpy(L.ranges_fp64, ranges, sizeof ranges);  // little-endian host and device: low word first
  L.raw_width = m.raw_width;
  L.raw_height = m.raw_height;
  L.frames = kernel_frames(plan, m);
  L.window_auto = m.window_auto ? PS_WINDOW_AUTO : m.window_drawn() ? PS_WINDOW_DRAWN : PS_WINDOW_FIXED;
  L.subjects = static_cast<int32_t>(cat.subjects.size());
  return L;
}

}  // namespace

ViewDerivations::ViewDerivations(const Catalogue& cat, const AssetSet& assets, cl::Context& ctx)
    : cat_(cat), assets_(assets), ctx_(ctx), per_plan_(capacity_for(cat)), cache_(per_plan_) {}

std::string ViewDerivations::key(const Plan& plan, int view, bool noise_free) {
  // images: whether per-pixel noise is drawn pixel by pixel (Plan::pixel_noise_per_pixel);
  // fused: which paths run, so which path's tables an entry holds.
  return table_key(plan, "view=" + std::to_string(view) + ";noise_free=" + std::to_string(noise_free) + ";images=" +
                             std::to_string(plan.images) + ";fused=" + std::to_string(plan.fidelity.fused));
}

std::shared_ptr<ViewDerived> ViewDerivations::operator()(const Plan& plan, int view, bool noise_free) {
  std::shared_ptr<ViewDerived>& entry = cache_[key(plan, view, noise_free)];
  if (entry) return entry;
  auto d = std::make_shared<ViewDerived>();
  const Sensor& s = cat_.sensors[view];
  d->model = plan.model.for_view(s);
  if (noise_free) {
    d->model.netd = 0;
    d->model.drawn[PS_DRAWN_NETD] = d->model.drawn[PS_DRAWN_FRAMES] = {};
  }
  const ModelSettings& m = d->model;
  d->L = settings(cat_, plan, m, view);
  const bool fp64 = plan.fidelity.precision == Precision::fp64;
  if (plan.model.model == Model::physics) {
    const PhysicsTables t = physics_tables(cat_, assets_, plan, m, view);
    d->L.tables = t.at;
    d->phys = params(ctx_, fp64, t.values);
    d->raw_values = static_cast<size_t>(m.raw_width) * m.raw_height;
    // A second field for the stage chain; physics_raw's row sums; stage_mmw_display's
    // interpolated rows; ir_surface_fused's row blur and row spans.
    d->scratch_values =
        std::max({s.pixels(), size_t(s.width) + m.raw_width, mmw_display_scratch(s, m.raw_width, m.raw_height),
                  s.pixels() + 2 * size_t(s.height)});
  } else {
    d->phys = params(ctx_, fp64, drawn_params(m));
  }
  entry = d;
  return d;
}

}  // namespace portalsim::opencl
