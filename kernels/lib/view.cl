// Helpers (kernels/lib/): what every camera-view kernel takes and where its work-item is
// (VIEW_STAGE_ARGS and the *_STAGE_* rows), and the rows of a subject's base image.

// The arguments of every camera-view stage kernel (stage_<name>) and of the fused
// render_view, in one order, so the host sets them in one place.
//   sprites: int4 (atlas offset, width, height, padded offset) per (sprite set, variant)
//   noise_offsets: atlas offset of each noise pattern, then of its padded copy
//   places:  int2 (x0, y0) per (view, variant, region), the sprite centred in its region;
//            then int2 (0, dy) per (subject, view, region), its place's move with the
//            subject's height (Sensor::subject_dy)
//   records: the view's placement record per scenario (kernels/contract.h, PS_REC_*)
//   field:   the view's values before display, n * height * width, at the build's precision
//   phys:    the view's parameters (kernels/contract.h): its drawn ranges (PsPhys::drawn), and
//            the physics model's (PsPhysMmw and PsPhysIr)
//   raw:     physics: the MMW raw grid, n * raw_height * raw_width
//   scratch: physics: a second field, for stages that cannot work in place
//   indices: each scenario's global index where the batch is not contiguous, else null
//            (scenario_index)
#define VIEW_STAGE_ARGS                                                                                          \
  global const uchar *atlas, global const int *bases, global const int4 *sprites, global const int2 *places,     \
      global const int *noise_offsets, global const float *noise_gains, global const uchar *subject,             \
      global const short *objects, PsViewLaunch L, param alpha, global int *records,                                     \
      global real *field, global uchar *out, global const param *phys, global real *raw, global real *scratch,   \
      global const ulong *indices

// The scenario and image row of a work-item (one per (scenario, row)).
#define VIEW_STAGE_ROW                                           \
  const size_t gid = get_global_id(0);                           \
  const uint i = (uint)(gid / (size_t)L.height);                 \
  const int y = (int)(gid % (size_t)L.height);                   \
  if (i >= L.n) return;                                          \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);              \
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);      \
  global const int* rec = records + (size_t)i * PS_REC_LEN;      \
  const size_t row0 = ((size_t)i * L.height + y) * L.width;      \
  (void)seed;                                                    \
  (void)index

// The scenario of a work-item (stages that take a whole view per work-item).
#define VIEW_STAGE_SCENARIO                                  \
  const uint i = (uint)get_global_id(0);                     \
  if (i >= L.n) return;                                      \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);          \
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);  \
  (void)seed;                                                \
  (void)index

// The scenario and raw-grid row of a work-item (physics stages on the MMW raw grid, one
// per (scenario, raw row)); r points at that raw row.
#define RAW_STAGE_ROW                                                                   \
  const size_t gid = get_global_id(0);                                                  \
  const uint i = (uint)(gid / (size_t)L.raw_height);                                    \
  const int j = (int)(gid % (size_t)L.raw_height);                                      \
  if (i >= L.n) return;                                                                 \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);                                     \
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);                             \
  global preal* r = (global preal*)raw + ((size_t)i * L.raw_height + j) * L.raw_width;  \
  (void)seed;                                                                           \
  (void)index

inline global const uchar* base_row(global const uchar* atlas, global const int* bases, global const uchar* subject,
                                    const PsViewLaunch* L, uint i, int y) {
  return atlas + bases[subject[i] * L->views + L->view] + (size_t)y * L->width;
}
// The same row of the base's fold pattern (host: AssetSet::folds), after every subject's bases.
inline global const uchar* fold_row(global const uchar* atlas, global const int* bases, global const uchar* subject,
                                    const PsViewLaunch* L, uint i, int y) {
  return atlas + bases[(L->subjects + subject[i]) * L->views + L->view] + (size_t)y * L->width;
}
