#include "backend/opencl/view_launch.h"

namespace portalsim::opencl {

ViewLaunch::ViewLaunch(Device& d, Kernels& K, const Plan& p, int view, const DeviceBatch& b, const cl::Buffer& out,
                       bool uses_field, bool tabulated, bool noise_free)
    : plan(p),
      sensor(d.cat.sensors[view]),
      chain(sensor.chain_for(p.model.model)),
      batch(b),
      derived(d.derived(p, view, noise_free)),
      K_(K),
      d_(d) {
  const size_t n = b.n;
  const Sensor& s = sensor;
  cl::Context& ctx = d.ctx();
  const DeviceCatalogue& c = d.data;
  PsViewLaunch L = derived->L;
  L.n = static_cast<uint32_t>(n);
  L.seed_lo = b.seed.s[0];
  L.seed_hi = b.seed.s[1];
  L.first_lo = b.first.s[0];
  L.first_hi = b.first.s[1];
  if (tabulated) L.flags |= PS_FLAG_TABULATED;
  cl::Buffer field = uses_field ? d.field.at_least(ctx, n * s.pixels() * K.real_bytes()) : out;
  // A record per scenario (kernels/contract.h, PS_REC_LEN): a layer per region at most.
  const size_t rec_len = PS_REC_LAYERS + d.cat.regions.size() * PS_LAYER_LEN;
  cl::Buffer& records = d.records.at_least(ctx, n * rec_len * sizeof(cl_int));
  cl::Buffer& raw = d.raw.at_least(ctx, n * derived->raw_values * K.real_bytes());
  cl::Buffer& scratch = d.view_scratch.at_least(ctx, n * derived->scratch_values * K.real_bytes());
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
                        .records = records,
                        .field = field,
                        .out = out,
                        .phys = derived->phys,
                        .raw = raw,
                        .scratch = scratch,
                        .indices = b.indices};
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
      per_scenario = static_cast<size_t>(derived->model.raw_height);
      break;
    case StageItems::scenarios:
      break;
  }
  run(k.kernel, batch.n * per_scenario);
}

}  // namespace portalsim::opencl
