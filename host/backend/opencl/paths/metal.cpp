// The metal detector's zones: the thesis model's influence tables (kernels/metal.cl), or
// the physics model's coil fields and polarizability tensors (kernels/metal_physics.cl, in
// fp64).
#include "backend/opencl/buffers.h"
#include "backend/opencl/launch.h"
#include "backend/opencl/metal_map.h"
#include "backend/opencl/paths/paths.h"
#include "backend/opencl/physics_params.h"
#include "base/error.h"

namespace portalsim::opencl {

// The coil model's tables (kernels/contract.h, PS_MZ_*, PS_MR_* and PS_MV_*): each variant's
// polarizability tensor and long side, as the reference takes them from the catalogue.
MetalPath::MetalPath(Device& d) : d_(d) {
  const Catalogue& cat = d.cat;
  if (!cat.metal_physics.present) return;
  const MetalPhysics& mp = cat.metal_physics;
  const size_t S = cat.subjects.size(), R = cat.regions.size();
  const std::vector<cl_double> zones = metal_zone_records(mp);
  std::vector<cl_double> regions(S * R * PS_MR_LEN, 0.0), tensors;
  // Each subject's region centres: the places, moved with its height, in the field.
  for (int r = 0; r < cat.region_count(); ++r) {
    const int k = first_view(cat.sensors, r);
    if (k < 0) continue;
    const Sensor& s = cat.sensors[k];
    for (size_t j = 0; j < S; ++j) {
      const Rect rc = s.place(static_cast<int>(j), r);
      cl_double* rec = &regions[(j * R + r) * PS_MR_LEN];
      rec[PS_MR_COL] = s.field_col(rc.x + rc.w / 2.0);
      rec[PS_MR_ROW] = s.field_row(rc.y + rc.h / 2.0);
      rec[PS_MR_FIELD_PER_COL] = s.field_per_col();
      rec[PS_MR_FIELD_PER_ROW] = s.field_per_row();
      rec[PS_MR_JITTER_X] = s.jitter_scale_x;
      rec[PS_MR_JITTER_Y] = s.jitter_scale_y;
    }
  }
  for (size_t v = 0; v < cat.variant_list.size(); ++v) {
    for (double e : cat.polarizability(static_cast<int>(v))) tensors.push_back(e);
    for (double e : cat.long_side(static_cast<int>(v))) tensors.push_back(e);
    tensors.push_back(0.0);  // long side's y: a catalogue variant lies across the walk
  }
  static_assert(PS_MV_LEN == 12 && PS_MV_LONG_X == 9 && PS_MV_LONG_Z == 10 && PS_MV_LONG_Y == 11);
  zone_rec_ = constant(d.ctx(), zones);
  region_rec_ = constant(d.ctx(), regions);
  tensors_ = constant(d.ctx(), tensors);
}

void MetalPath::run(Kernels& K, const Plan& plan, const DeviceBatch& b, BatchOutput& out) {
  const Catalogue& cat = d_.cat;
  cl::Buffer& metal = out_.at_least(d_.ctx(), b.n * cat.zones);
  const cl_uint n = static_cast<cl_uint>(b.n);
  // The run's drawn ranges: the kernels draw each scenario's detector noise from them.
  const cl::Buffer drawn = params(d_.ctx(), K.fp64(), drawn_params(plan.model));
  if (plan.model.model == Model::physics) {
    if (!d_.rt.has_fp64())
      throw EnvironmentError("--model physics computes metal zones in fp64, and " + d_.rt.device_name() +
                             " has no cl_khr_fp64; --backend reference works without it");
    if (!cat.metal_physics.present) throw InputError("--model physics: the catalogue has no [metal.physics] section");
    const MetalPhysics& mp = cat.metal_physics;
    // The reference's jitter, (jitter * scale) * (2u - 1), in each region's placing view.
    enqueue(d_.queue(), K["metal_physics"], K.fp64(),
            MetalPhysicsArgs{.zone_rec = zone_rec_,
                             .region_rec = region_rec_,
                             .tensors = tensors_,
                             .base_zones = d_.data.base_zones,
                             .subject = b.subject,
                             .objects = b.objects,
                             .n = n,
                             .seed = b.seed,
                             .first = b.first,
                             .indices = b.indices,
                             .drawn = drawn,
                             .jitter = plan.model.jitter,
                             .half_width = kFieldWidth / 2.0,
                             .scale = cat.metres_per_field_unit(),
                             .body_height = mp.body_height,
                             .out = metal},
            b.n);
  } else {
    enqueue(d_.queue(), K["metal_zones"], K.fp64(),
            MetalZonesArgs{.influence = d_.data.influence,
                           .variant_category = d_.data.categories,
                           .base_zones = d_.data.base_zones,
                           .subject = b.subject,
                           .objects = b.objects,
                           .n = n,
                           .seed = b.seed,
                           .first = b.first,
                           .indices = b.indices,
                           .drawn = drawn,
                           .out = metal},
            b.n);
  }
  d_.queue().enqueueReadBuffer(metal, CL_FALSE, 0, b.n * cat.zones, out.metal.data());
}

}  // namespace portalsim::opencl
