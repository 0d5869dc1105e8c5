// The physics MMW camera's declared fast path: radiometry -> optics -> sample -> netd in one
// work-item per scenario, writing the raw grid that stage_mmw_display then shows. All of
// optics and sampling is linear, so the raw grid is the subject's bare raw grid (a table)
// plus, for each view row an object crosses, that row's change (composite minus bare, in
// kelvin) projected through the folded weights: raw[r][c] += wy[r][y] sum_x wx[c][x] d(x, y).
// Tested against the chain of stage kernels and the reference (tests/physics_test.cpp).

kernel void physics_raw(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)objects, (void)alpha,
      (void)field, (void)out;
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);
  global const int* rec = records + (size_t)i * PS_REC_LEN;
  if (physics_tabulated(rec, &L)) return;  // physics_features sums its tables instead
  const int W = L.width, H = L.height, RW = L.raw_width, RH = L.raw_height, cells = RW * RH;
  global preal* r = (global preal*)raw + (size_t)i * cells;
  // Scratch: one view row's change per raw column, then its change per view pixel.
  global preal* restrict acc = (global preal*)scratch + (size_t)i * (RW + W);
  global preal* restrict d = acc + RW;
  const int s = subject[i];
  global const param* bare = phys + L.tables.base + (size_t)s * cells;
  // The scenario's illumination moves the bare grid along its change (PS_SCENE_BARE); its
  // outfit makes it from its gray grid (PS_CLOTHING_GRIDS): gain G + offset, every raw cell's
  // weights summing to 1.
  const SceneDraw scene = scene_draw(phys, seed, index);
  preal gain, offset, lv[PS_MAX_LAYERS];
  subject_kelvin(&scene, s, &gain, &offset);
  if (scene.outfit >= 0) {
    global const param* gray = phys + (int)phys[(int)phys_common(phys)->clothing + PS_CLOTHING_GRIDS] + (size_t)s * cells;
    for (int k = 0; k < cells; ++k) r[k] = gray_kelvin(gain, (preal)gray[k], offset);
    // Its folds: the fold grids' share-weighted gray A and share B (PS_CLOTHING_FOLD_GRIDS) add
    // fold (gain A + (offset - fold_t) B), the raw grid of fold m (v - fold_t) over the bare body.
    if (scene.fold != 0) {
      const int grids = (int)phys[(int)phys_common(phys)->clothing + PS_CLOTHING_FOLD_GRIDS];
      global const param* fa = phys + grids + (size_t)s * cells;
      global const param* fb = fa + (size_t)L.subjects * cells;
      for (int k = 0; k < cells; ++k)
        r[k] += scene.fold * (gain * (preal)fa[k] + (offset - scene.fold_t) * (preal)fb[k]);
    }
  } else if (scene.at == 0) {
    for (int k = 0; k < cells; ++k) r[k] = (preal)bare[k];
  } else {
    global const param* moved = phys + scene.at + PS_SCENE_BARE(L.subjects, L.variants) + (size_t)s * cells;
    for (int k = 0; k < cells; ++k) r[k] = (preal)bare[k] + (preal)moved[k] * scene.t;
  }

  // The view rows any object can touch.
  int y_lo = H, y_hi = 0;
  for (int j = 0; j < rec[PS_REC_COUNT]; ++j) {
    const int2 rows = layer_rows(rec + PS_REC_LAYERS + j * PS_LAYER_LEN, L.flags);
    y_lo = min(y_lo, max(rows.x, 0));
    y_hi = max(y_hi, min(rows.y, H));
  }
  global const param* object_t = variant_values(&scene, L.subjects);
  global const param* wx = phys + L.tables.wx;
  global const param* wy = phys + L.tables.wy;
  global const param* cband = phys + L.tables.cband;
  global const param* rband = phys + L.tables.rband;
  for (int y = y_lo; y < y_hi; ++y) {
    Layers Ly;
    composite_layers(&Ly, rec, &L, y);
    if (Ly.count == 0) continue;
    layer_values(&Ly, object_t, &scene, L.subjects, lv);
    int x_lo = W, x_hi = 0;
    for (int k = 0; k < Ly.count; ++k) {
      x_lo = min(x_lo, max(Ly.x0[k], 0));
      x_hi = max(x_hi, min(Ly.x0[k] + Ly.width[k], W));
    }
    if (x_lo >= x_hi) continue;
    global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
    for (int x = x_lo; x < x_hi; ++x) {
      const preal t0 = gray_kelvin(gain, (preal)base[x], offset);
      d[x] = lay_values(&Ly, atlas, x, lv, t0) - t0;
    }
    if (scene.fold != 0) {  // the change passes the folds as the bare body does
      global const uchar* m = fold_row(atlas, bases, subject, &L, i, y);
      for (int x = x_lo; x < x_hi; ++x) d[x] *= fold_gain(&scene, m[x]);
    }
    // Each raw column's share of the row: its weights (zero outside its band) against
    // the change, as dot products over the span; fp32 builds in 16-lane partial sums.
    const int c_lo = (int)cband[2 * x_lo], c_hi = (int)cband[2 * (x_hi - 1) + 1];
    for (int c = c_lo; c <= c_hi; ++c) {
      global const param* restrict w = wx + (size_t)c * W;
      int x = x_lo;
      preal sum = 0;
#if !defined(PRECISION_FP64)
      float16 part = 0.0f;
      for (; x + 16 <= x_hi; x += 16) part += LOADF16(global, w + x) * LOADF16(global, d + x);
      const float8 p8 = part.lo + part.hi;
      const float4 p4 = p8.lo + p8.hi;
      const float2 p2 = p4.lo + p4.hi;
      sum = p2.x + p2.y;
#endif
      for (; x < x_hi; ++x) sum += (preal)w[x] * d[x];
      acc[c] = sum;
    }
    for (int rr = (int)rband[2 * y]; rr <= (int)rband[2 * y + 1]; ++rr) {
      const preal w = (preal)wy[(size_t)rr * H + y];
      for (int c = c_lo; c <= c_hi; ++c) r[rr * RW + c] += w * acc[c];
    }
  }

  // The netd stage: the scenario's frames averaged (kernels/lib/physics.cl, netd_frames).
  int frames;
  const preal sd = mmw_noise_of(phys, L.frames, seed, index, &frames);
  if (sd > 0) netd_frames(r, cells, sd, frames, seed, index, L.view, phys + L.tables.gauss, L.flags & PS_FLAG_FAST_DRAWS);
}
