// Features-only runs of the physics model from the MMW raw grid (host/backend/opencl/
// raw_grid_pooling.h), one work-item per scenario and pooled view. Each feature, in kelvin
// before the display window: the scenario's tables where physics_tabulated holds (the
// subject's bare features, each object's change alone, and each meeting pair's correction;
// object_range: per (subject, variant, region), then per (subject, pair), its entries
// [x, y); pair_index: per (variant, region, variant, region), its pair's number or -1, the
// pairs being those whose boxes meet on some subject, dims.s6 of them),
// or else its weighted sum of the raw cells physics_raw wrote; then the NETD's noise drawn
// in feature space (Ly Z Lx^T for the blocks, B z + Lr z_r for the regions); then the
// window (the scenario's, where its ends are drawn), clamped to 0..255: the mean of its
// unrounded, unclamped pixels.
//   dims: blocks_x, blocks_y, band_x, band_y, regions (RawGridNoise), the block columns' first.
//   noise: dx, dy (per block, raw_grid_pooling.h), region_blocks, region_own.
//   work space per scenario (PS_FEATURE_SPACE): the features, band_x zeros, Z (blocks_y x
//   blocks_x) and the regions' draws, band_y rows of zeros, Z Lx^T; private where it fits,
//   else global scratch.

// The NETD's noise in feature space, added to acc (see above); z (after band_x zeros)
// and w are the work space: feature_noise_private and feature_noise_global. Dot products
// in fp32 builds take 16 lanes with two accumulators (a single scalar sum waits on each add).
#if defined(PRECISION_FP64)
#define DOT_CELLS(SPACE, t, a, b, count) \
  for (int q = 0; q < count; ++q) t += (preal)a[q] * b[q];
#else
#define DOT_CELLS(SPACE, t, a, b, count)                                \
  {                                                                     \
    int q = 0;                                                          \
    float16 s0 = 0.0f, s1 = 0.0f;                                       \
    for (; q + 32 <= count; q += 32) {                                  \
      s0 += LOADF16(global, a + q) * LOADF16(SPACE, b + q);             \
      s1 += LOADF16(global, a + q + 16) * LOADF16(SPACE, b + q + 16);   \
    }                                                                   \
    const float16 s = s0 + s1;                                  \
    const float8 s8 = s.lo + s.hi;                              \
    const float4 s4 = s8.lo + s8.hi;                            \
    t += s4.x + s4.y + s4.z + s4.w;                             \
    for (; q < count; ++q) t += (preal)a[q] * b[q];             \
  }
#endif
#define FEATURE_NOISE(SPACE)                                                                                      \
  inline void feature_noise_##SPACE(SPACE preal* restrict acc, SPACE preal* restrict z, SPACE preal* restrict w, \
                                    int8 dims, global const param* noise, preal sd, uint2 seed, ulong index,    \
                                    int view, global const param* table) {                                     \
    const int BX = dims.s0, BY = dims.s1, band_x = dims.s2, band_y = dims.s3, R = dims.s4;                       \
    const int blocks = BX * BY;                                                                                \
    for (int k = -band_x; k < 0; ++k) z[k] = 0;                                                                \
    for (int k = -band_y * BX; k < 0; ++k) w[k] = 0;                                                           \
    gauss_cells_##SPACE(z, blocks + R, (preal)1, false, seed, index, PS_STREAM_FEATURE_NOISE, view, table);    \
    global const param* restrict dx = noise;                                                                   \
    global const param* restrict dy = dx + (band_x + 1) * blocks;                                              \
    global const param* restrict rb = dy + (band_y + 1) * blocks;                                              \
    global const param* restrict ro = rb + R * blocks;                                                         \
    /* W = Z Lx^T: W[q] = sum_d Lx[bx][bx - d] Z[q - d], the factors laid out per block (zero */              \
    /* where bx - d < 0, which reads the row before or the zeros before Z). */                                 \
    for (int q = 0; q < blocks; ++q) w[q] = (preal)dx[q] * z[q];                                               \
    for (int d = 1; d <= band_x; ++d)                                                                          \
      for (int q = 0; q < blocks; ++q) w[q] += (preal)dx[d * blocks + q] * z[q - d];                           \
    /* The blocks: F = Ly W, F[q] = sum_d Ly[by][by - d] W[q - d BX]. */                                       \
    for (int d = 0; d <= band_y; ++d)                                                                          \
      for (int q = 0; q < blocks; ++q) acc[q] += sd * (preal)dy[d * blocks + q] * w[q - d * BX];               \
    for (int k = 0; k < R; ++k) {                                                                              \
      global const param* restrict b = rb + (size_t)k * blocks;                                                \
      preal t = 0;                                                                                             \
      DOT_CELLS(SPACE, t, b, z, blocks);                                                                       \
      for (int m = 0; m <= k; ++m) t += (preal)ro[k * R + m] * z[blocks + m];                                  \
      acc[blocks + k] += sd * t;                                                                               \
    }                                                                                                          \
  }
FEATURE_NOISE(global)
FEATURE_NOISE(private)

// A scenario's features of the view into acc (kelvin), its noise, then the row (gray).
#define VIEW_FEATURES(SPACE)                                                                                       \
  inline void view_features_##SPACE(SPACE preal* restrict acc, SPACE preal* restrict z, SPACE preal* restrict w, \
                                    global float* restrict row, uint i, const PsViewLaunch* L,                  \
                                    global const preal* raw, global const int* first, global const int* cells,   \
                                    global const param* weights, global const int* columns, int count,           \
                                    int raw_cells, global const param* phys, global const int* records,          \
                                    global const uchar* subject, global const short* objects,                    \
                                    global const param* base_features, global const int2* object_range,           \
                                    global const int* pair_index, global const int* object_feature,           \
                                    global const param* object_value,          \
                                    preal sd, int8 dims, global const param* noise, ulong index) {                           \
    const int blocks = dims.s0 * dims.s1;                                                                      \
    global const int* rec = records + (size_t)i * PS_REC_LEN;                                                  \
    if (physics_tabulated(rec, L)) {                                                                           \
      const int s = subject[i];                                                                                \
      global const param* restrict bare = base_features + (size_t)s * count;                                   \
      for (int f = 0; f < count; ++f) acc[f] = (preal)bare[f];                                                 \
      int tab[PS_MAX_LAYERS], n = 0; /* each layer's (variant, region) */                                      \
      for (int r = 0; r < PS_REGIONS; ++r) {                                                                   \
        const int v = objects[(size_t)i * PS_REGIONS + r];                                                     \
        if (v < 0 || !((L->region_mask >> r) & 1u)) continue;                                                  \
        const int t = v * PS_REGIONS + r;                                                                      \
        tab[n++] = t;                                                                                          \
        const int u = s * L->variants * PS_REGIONS + t;                                                        \
        for (int e = object_range[u].x; e < object_range[u].y; ++e) acc[object_feature[e]] += object_value[e];   \
      }                                                                                                        \
      const int combos = L->variants * PS_REGIONS, pairs0 = L->subjects * combos;                              \
      for (int j = 0; j < n; ++j)                                                                              \
        for (int k = j + 1; k < n; ++k) {                                                                      \
          if (!layers_meet(rec + PS_REC_LAYERS + j * PS_LAYER_LEN, rec + PS_REC_LAYERS + k * PS_LAYER_LEN))    \
            continue;                                                                                          \
          const int pair = pair_index[tab[j] * combos + tab[k]];                                               \
          if (pair < 0) continue;                                                                              \
          const int u = pairs0 + s * dims.s6 + pair;                                                           \
          for (int e = object_range[u].x; e < object_range[u].y; ++e) acc[object_feature[e]] += object_value[e];   \
        }                                                                                                      \
    } else {                                                                                                   \
      global const preal* grid = raw + (size_t)i * raw_cells;                                                  \
      for (int f = 0; f < count; ++f) {                                                                        \
        preal t = 0;                                                                                           \
        for (int k = first[f]; k < first[f + 1]; ++k) t += (preal)weights[k] * grid[cells[k]];                 \
        acc[f] = t;                                                                                            \
      }                                                                                                        \
    }                                                                                                          \
    if (sd > 0)                                                                                                \
      feature_noise_##SPACE(acc, z, w, dims, noise, sd, (uint2)(L->seed_lo, L->seed_hi),                       \
                            index, L->view, phys + L->tables.gauss);            \
    preal lo = (preal)phys_common(phys)->window_min, hi = (preal)phys_common(phys)->window_max;                          \
    if (L->window_auto == PS_WINDOW_DRAWN) /* the scenario's window, as stage_window draws it */              \
      drawn_window(phys, (uint2)(L->seed_lo, L->seed_hi), index, &lo, &hi);  \
    const preal scale = (preal)255 / (hi - lo);                                                                \
    global float* restrict fb = row + dims.s5; /* the blocks' columns are contiguous */                        \
    for (int f = 0; f < blocks; ++f) fb[f] = clamp((float)((acc[f] - lo) * scale), 0.0f, 255.0f);              \
    for (int f = blocks; f < count; ++f) row[columns[f]] = clamp((float)((acc[f] - lo) * scale), 0.0f, 255.0f); \
  }
VIEW_FEATURES(global)
VIEW_FEATURES(private)

kernel void physics_features(global const preal* raw, global const int* first, global const int* cells,
                             global const param* weights, global const int* columns, int count, int raw_cells,
                             global const param* phys, int row_len, global float* features, PsViewLaunch L,
                             global const int* records, global const uchar* subject, global const short* objects,
                             global const param* base_features, global const int2* object_range,
                             global const int* pair_index, global const int* object_feature,
                             global const param* object_value, param netd_lo, param netd_hi, int2 frames,
                             int8 dims, global const param* noise, global preal* scratch,
                             global const ulong* indices) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);
  // The NETD over the frames' mean: netd_lo where neither is drawn (the host's NETD /
  // sqrt(frames)), else the scenario's draw (kernels/lib/physics.cl).
  int one;
  const preal sd = netd_hi <= netd_lo && frames.y <= frames.x
                       ? (preal)netd_lo
                       : mmw_noise_drawn((preal)netd_lo, (preal)netd_hi, frames.x, frames.y, true,
                                         (uint2)(L.seed_lo, L.seed_hi), index, &one);
  global float* row = features + (size_t)i * row_len;
  const int band_x = dims.s2, band_y = dims.s3, zlen = dims.s0 * dims.s1 + dims.s4;
  const int space = PS_FEATURE_SPACE(dims.s0, dims.s1, band_x, band_y, dims.s4);
  if (space <= PS_FEATURE_NOISE_PRIVATE) {
    preal work[PS_FEATURE_NOISE_PRIVATE];
    view_features_private(work, work + count + band_x, work + count + band_x + zlen + band_y * dims.s0, row, i, &L,
                          raw, first, cells,
                          weights, columns, count, raw_cells, phys, records, subject, objects, base_features,
                          object_range, pair_index, object_feature, object_value, sd, dims, noise, index);
  } else {
    global preal* work = scratch + (size_t)(i - get_global_offset(0)) * space;  // a launch per chunk
    view_features_global(work, work + count + band_x, work + count + band_x + zlen + band_y * dims.s0, row, i, &L,
                         raw, first, cells,
                         weights, columns, count, raw_cells, phys, records, subject, objects, base_features,
                         object_range, pair_index, object_feature, object_value, sd, dims, noise, index);
  }
}
