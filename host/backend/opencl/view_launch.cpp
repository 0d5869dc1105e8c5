#include "backend/opencl/view_launch.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "backend/opencl/display_tables.h"

namespace portalsim::opencl {

namespace {

PsViewLaunch settings(const Catalogue& cat, const Plan& plan, int view, const DeviceBatch& b, bool tabulated) {
  const Sensor& s = cat.sensors[view];
  PsViewLaunch L{};
  L.n = static_cast<uint32_t>(b.n);
  L.view = view;
  L.views = static_cast<int32_t>(cat.sensors.size());
  L.sprite_set = s.sprite_set;
  L.variants = static_cast<int32_t>(cat.variant_list.size());
  L.region_mask = s.region_mask;
  L.width = s.width;
  L.height = s.height;
  L.seed_lo = b.seed.s[0];
  L.seed_hi = b.seed.s[1];
  L.first_lo = b.first.s[0];
  L.first_hi = b.first.s[1];
  L.patterns = static_cast<int32_t>(cat.noise.size());
  L.tile_size = cat.images.noise_size;
  L.flags = (s.pattern_noise && plan.model.pattern_noise ? PS_FLAG_PATTERN_NOISE : 0) |
            (plan.pixel_noise_per_pixel() ? PS_FLAG_PIXEL_NOISE : 0) | (plan.model.bilinear ? PS_FLAG_BILINEAR : 0) |
            (plan.model.transforms() ? PS_FLAG_AFFINE : 0) | (plan.model.flip ? PS_FLAG_FLIP : 0) |
            (tabulated ? PS_FLAG_TABULATED : 0) | (plan.physics_draws_approximated() ? PS_FLAG_FAST_DRAWS : 0);
  L.jitter_x = static_cast<float>(plan.model.jitter * s.jitter_scale_x);
  L.jitter_y = static_cast<float>(plan.model.jitter * s.jitter_scale_y);
  L.rotate_lo = static_cast<float>(plan.model.rotate_lo);
  L.rotate_hi = static_cast<float>(plan.model.rotate_hi);
  L.scale_lo = static_cast<float>(plan.model.scale_lo);
  L.scale_hi = static_cast<float>(plan.model.scale_hi);
  const double ranges[4] = {plan.model.rotate_lo, plan.model.rotate_hi, plan.model.scale_lo, plan.model.scale_hi};
  std::memcpy(L.ranges_fp64, ranges, sizeof ranges);  // little-endian host and device: low word first
  L.raw_width = plan.model.raw_width;
  L.raw_height = plan.model.raw_height;
  L.frames = kernel_frames(plan);
  L.window_auto = plan.model.window_auto;
  L.subjects = static_cast<int32_t>(cat.subjects.size());
  return L;
}

}  // namespace

ViewLaunch::ViewLaunch(Device& d, Kernels& K, const Plan& p, int view, const DeviceBatch& b, const cl::Buffer& out,
                       bool uses_field, bool tabulated)
    : plan(p), sensor(d.cat.sensors[view]), chain(sensor.chain_for(p.model.model)), batch(b), K_(K), d_(d) {
  const size_t n = b.n;
  const Sensor& s = sensor;
  cl::Context& ctx = d.ctx();
  const DeviceCatalogue& c = d.data;
  PsViewLaunch L = settings(d.cat, p, view, b, tabulated);
  cl::Buffer field = uses_field ? d.field.at_least(ctx, n * s.pixels() * K.real_bytes()) : out;
  // A record per scenario (kernels/contract.h, PS_REC_LEN): a layer per region at most.
  const size_t rec_len = PS_REC_LAYERS + d.cat.regions.size() * PS_LAYER_LEN;
  cl::Buffer& records = d.records.at_least(ctx, n * rec_len * sizeof(cl_int));
  cl::Buffer phys = d.physics(K.fp64(), p, view, L);
  const bool physics = p.model.model == Model::physics;
  const ModelSettings& m = p.model;
  cl::Buffer& raw = d.raw.at_least(ctx, physics ? n * m.raw_width * m.raw_height * K.real_bytes() : 1);
  // Physics, per scenario: a second field for the stage chain; physics_raw's row sums;
  // stage_mmw_display's interpolated rows; ir_surface_fused's row blur and row spans.
  const size_t scratch_values =
      std::max({s.pixels(), size_t(s.width) + m.raw_width, mmw_display_scratch(s, m.raw_width, m.raw_height),
                s.pixels() + 2 * size_t(s.height)});
  cl::Buffer& scratch = d.view_scratch.at_least(ctx, physics ? n * scratch_values * K.real_bytes() : 1);
  args_ = ViewStageArgs{.atlas = c.atlas,
                        .bases = c.bases,
                        .sprites = c.sprites,
                        .places = c.places,
                        .noise_offsets = c.noise_offsets,
                        .noise_gains = c.noise_gains,
                        .subject = b.subject,
                        .objects = b.objects,
                        .L = L,
                        .alpha = {d.cat.images.alpha},
                        .sigma = {m.pixel_sigma},
                        .records = records,
                        .field = field,
                        .out = out,
                        .phys = phys,
                        .raw = raw,
                        .scratch = scratch};
}

void ViewLaunch::run(std::string_view kernel, size_t items) {
  enqueue(d_.queue(), K_[kernel], K_.fp64(), args_, items);
}

void ViewLaunch::run(const StageKernel& k) {
  size_t per_scenario = 1;
  switch (k.items) {
    case StageItems::view_rows:
      per_scenario = static_cast<size_t>(sensor.height);
      break;
    case StageItems::raw_rows:
      per_scenario = static_cast<size_t>(plan.model.raw_height);
      break;
    case StageItems::scenarios:
      break;
  }
  run(k.kernel, batch.n * per_scenario);
}

}  // namespace portalsim::opencl
