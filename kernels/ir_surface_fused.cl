// The physics IR camera's declared fast path: contact_shadow -> heat_spread -> ir_surface
// in one work-item per scenario, leaving the surface in kelvin in `field` for the chain's
// remaining stage kernels (ir_surface_fused), or, where only ir_display is left, showing
// it straight away (ir_surface_display_fused). The shadow is zero outside the objects'
// footprints, and the blur of zero is zero, so each row's shadow is drawn and blurred only
// over its objects' span and the blur's reach; every other pixel is the bare surface.
// Each value is the stage kernels' sum in their order with its zero terms left out (adding
// +0 to a sum that starts at +0 changes no bit): the same bits (tests/ir_physics_test.cpp).

// Pixels [a, b) of row T: the bare surface (ir_surface's kelvin of the base image), added
// to the values there (add) or alone, by gray_kelvin as stage_ir_surface (which
// -cl-fast-relaxed-math then rewrites alike). fp32 builds in explicit 16-lane vectors
// (LLVM's own stop at 8).
inline void bare_surface(global preal* restrict T, global const uchar* restrict base, int a, int b, preal gain,
                         preal offset, bool add) {
  int x = a;
#if !defined(PRECISION_FP64)
  if (add)
    for (; x + 16 <= b; x += 16)
      vstore16(vload16(0, T + x) + gray_kelvin(gain, convert_float16(load16(base + x)), offset), 0, T + x);
  else
    for (; x + 16 <= b; x += 16) vstore16(gray_kelvin(gain, convert_float16(load16(base + x)), offset), 0, T + x);
#endif
  if (add)
    for (; x < b; ++x) T[x] += gray_kelvin(gain, (preal)base[x], offset);
  else
    for (; x < b; ++x) T[x] = gray_kelvin(gain, (preal)base[x], offset);
}

// Scenario i's view. Scratch: the row blur, H x W, then each shadow row's blurred span
// [a, b) as two arrays of H ints (empty: (W, 0)). With display, each part of the field is
// shown as soon as it is made, while it is in cache.
inline void ir_surface_view(uint i, ulong index, const PsViewLaunch* L, global const uchar* atlas,
                            global const int* bases, global const uchar* subject, global const int* records,
                            global real* field, global uchar* out, global const param* phys, global real* scratch,
                            bool display) {
  global const int* rec = records + (size_t)i * PS_REC_LEN;
  const int W = L->width, H = L->height, R = L->tables.psf_radius;
  global preal* T = (global preal*)field + (size_t)i * H * W;
  global uchar* o = out + (size_t)i * H * W;
  global preal* S = (global preal*)scratch + (size_t)i * (H * W + 2 * H);
  global int* span_a = (global int*)(S + H * W);
  global int* span_b = span_a + H;
  const int s = subject[i];
  const SceneDraw scene = scene_draw(phys, (uint2)(L->seed_lo, L->seed_hi), index);
  preal gain, offset;
  subject_kelvin(&scene, s, &gain, &offset);
  // Folds change every body pixel (after the surface is whole, as stage_ir_surface): the view
  // is shown at the end then.
  const bool folds = scene.fold != 0, show = display && !folds;

  // The rows the objects can touch.
  int y_lo = H, y_hi = 0;
  for (int j = 0; j < rec[PS_REC_COUNT]; ++j) {
    const int2 rows = layer_rows(rec + PS_REC_LAYERS + j * PS_LAYER_LEN, L->flags);
    y_lo = min(y_lo, max(rows.x, 0));
    y_hi = max(y_hi, min(rows.y, H));
  }

  // contact_shadow over each row's span (into T), zero over the rest the row blur reads;
  // then heat_spread along the row (T -> S) as stage_optics_rows, over the span's reach.
  const int body_from = (int)phys[L->tables.off_body + s];
  global const param* taps = psf_taps(phys, L);
  preal on[PS_MAX_LAYERS], off[PS_MAX_LAYERS];
  for (int y = y_lo; y < y_hi; ++y) {
    Layers Ly;
    composite_layers(&Ly, rec, L, y);
    shadow_values(&Ly, L, phys, &scene, s, on, off);
    int a = W, b = 0;
    for (int k = 0; k < Ly.count; ++k) {
      a = min(a, max(Ly.x0[k], 0));
      b = max(b, min(Ly.x0[k] + Ly.width[k], W));
    }
    if (a >= b) {
      span_a[y] = W;
      span_b[y] = 0;
      continue;
    }
    global preal* restrict src = T + (size_t)y * W;
    for (int x = max(a - 2 * R, 0); x < a; ++x) src[x] = 0;
    global const uchar* restrict base_y = base_row(atlas, bases, subject, L, i, y);
    for (int x = a; x < b; ++x)
      src[x] = lay_values(&Ly, atlas, x, (int)base_y[x] >= body_from ? on : off, (preal)0);
    for (int x = b; x < min(b + 2 * R, W); ++x) src[x] = 0;
    global preal* restrict dst = S + (size_t)y * W;
    const int lo = max(a - R, 0), hi = min(b + R, W);
    const int in_lo = clamp(R, lo, hi), in_hi = clamp(W - R, in_lo, hi);  // no tap leaves the row
    for (int x = lo; x < hi; ++x) dst[x] = 0;
    for (int d = -R; d <= R; ++d) {
      const preal w = (preal)taps[d];
      for (int x = lo; x < in_lo; ++x) dst[x] += w * src[clamp(x + d, 0, W - 1)];
      for (int x = in_lo; x < in_hi; ++x) dst[x] += w * src[x + d];
      for (int x = in_hi; x < hi; ++x) dst[x] += w * src[clamp(x + d, 0, W - 1)];
    }
    span_a[y] = lo;
    span_b[y] = hi;
  }

  // heat_spread along columns (S -> T) as stage_optics_columns, each tap over its row's
  // span; then ir_surface: plus the bare surface, which alone is every other pixel (runs
  // of such rows at once: a view's rows lie one after another).
  global const uchar* base = base_row(atlas, bases, subject, L, i, 0);
  int bare_from = 0;
  for (int y = 0; y <= H; ++y) {
    int a = W, b = 0;
    for (int row = max(y - R, y_lo); row <= min(y + R, y_hi - 1); ++row) {
      a = min(a, span_a[row]);
      b = max(b, span_b[row]);
    }
    if (a >= b && y < H) continue;
    bare_surface(T, base, bare_from * W, y * W, gain, offset, false);
    if (show) ir_window(T, o, phys, bare_from * W, y * W);
    bare_from = y + 1;
    if (y == H) break;
    global preal* restrict dst = T + (size_t)y * W;
    for (int x = a; x < b; ++x) dst[x] = 0;
    for (int d = -R; d <= R; ++d) {
      const int row = clamp(y + d, 0, H - 1);
      if (row < y_lo || row >= y_hi) continue;
      const preal w = (preal)taps[d];
      global const preal* restrict src = S + (size_t)row * W;
      for (int x = span_a[row]; x < span_b[row]; ++x) dst[x] += w * src[x];
    }
    global const uchar* row_base = base + (size_t)y * W;
    bare_surface(dst, row_base, 0, a, gain, offset, false);
    bare_surface(dst, row_base, a, b, gain, offset, true);
    bare_surface(dst, row_base, b, W, gain, offset, false);
    if (show) ir_window(T, o, phys, y * W, (y + 1) * W);
  }
  if (!folds) return;
  for (int y = 0; y < H; ++y) fold_values(&scene, fold_row(atlas, bases, subject, L, i, y), T + (size_t)y * W, W);
  if (display) ir_window(T, o, phys, 0, H * W);
}

// The noisy kelvin as a value of its own, which fast math may not reassociate with the
// window's subtraction: stage_ir_netd stores it, and stage_ir_display reads it back.
#if __has_builtin(__arithmetic_fence)
#define IR_NOISY(t) __arithmetic_fence(t)
#else
#define IR_NOISY(t) (t)
#endif

#if !defined(PRECISION_FP64)
// Pixels p .. p + 127 of ir_noisy_window (those below `pixels`), their draws g.
inline void ir_noisy_block(global const float* restrict T, global uchar* restrict o, int p, int pixels,
                           const float16* g, float sd, float lo, float scale) {
  if (p + 128 <= pixels) {
    uchar16 l[8];
#pragma unroll
    for (int j = 0; j < 8; ++j) l[j] = window_level16(IR_NOISY(LOADF16(global, T + p + 16 * j) + sd * g[j]), lo, scale);
    store64(l[0], l[1], l[2], l[3], o + p);
    store64(l[4], l[5], l[6], l[7], o + p + 64);
    return;
  }
  for (int j = 0; j < 8; ++j) {
    const int q = p + 16 * j;
    if (q + 16 <= pixels) {
      store16(window_level16(IR_NOISY(LOADF16(global, T + q) + sd * g[j]), lo, scale), o + q);
    } else {
      float t[16];
      vstore16(g[j], 0, t);
      for (int k = q; k < pixels; ++k)
        o[k] = window_level(IR_NOISY(T[k] + sd * t[k - q]), lo, scale);
      break;
    }
  }
}
#endif

// ir_netd then ir_display over a view's whole surface T into o, in one pass: each pixel's
// kelvin plus sd times its table Gaussian (stage_ir_netd's sum, in its form) goes through
// the display window (ir_window) in registers, and no noisy field is written or read back.
// fp32 builds draw 256 pixels at a time (two blocks of gauss128's, their Philox rounds
// interleaved: gauss128x2), or 128 fast draws (ih128, PS_FLAG_FAST_DRAWS), and store 64
// levels at once; like the stage kernels, the last pixels past a whole 16 go one by one.
inline void ir_noisy_window(global const preal* restrict T, global uchar* restrict o, global const param* phys,
                            int pixels, preal sd, uint2 seed, ulong index, int view, global const param* table,
                            bool fast) {
  const preal lo = (preal)phys_common(phys)->window_min;
  const preal scale = (preal)255 / ((preal)phys_common(phys)->window_max - lo);
#if defined(PRECISION_FP64)
  for (int p = 0; p < pixels; ++p) {
    const preal g = fast ? ih_cell(seed, index, PS_STREAM_IR_NOISE, view, p)
                         : gauss_cell(seed, index, PS_STREAM_IR_NOISE, view, p, table);
    o[p] = window_level(IR_NOISY(T[p] + sd * g), lo, scale);
  }
#else
  if (fast) {
    for (int p = 0; p < pixels; p += 128) {
      float16 g[8];
      ih128(seed, index, PS_STREAM_IR_NOISE, view, p >> 7, g);
      ir_noisy_block(T, o, p, pixels, g, sd, lo, scale);
    }
    return;
  }
  for (int p = 0; p < pixels; p += 256) {
    float16 g[8], h[8];
    gauss128x2(seed, index, view, PS_STREAM_IR_NOISE, p >> 7, PS_STREAM_IR_NOISE, (p >> 7) + 1, table, g, h);
    ir_noisy_block(T, o, p, pixels, g, sd, lo, scale);
    if (p + 128 < pixels) ir_noisy_block(T, o, p + 128, pixels, h, sd, lo, scale);
  }
#endif
}

kernel void ir_surface_fused(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)objects, (void)alpha,
      (void)raw;
  ir_surface_view(i, scenario_index(indices, L.first_lo, L.first_hi, i), &L, atlas, bases, subject, records, field,
                  out, phys, scratch, false);
}

kernel void ir_surface_display_fused(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)objects, (void)alpha,
      (void)raw;
  ir_surface_view(i, scenario_index(indices, L.first_lo, L.first_hi, i), &L, atlas, bases, subject, records, field,
                  out, phys, scratch, true);
}

// The whole chain with noise: the surface as ir_surface_fused, then ir_netd and ir_display
// in one pass over it (ir_noisy_window), while it is in cache.
kernel void ir_surface_noise_display_fused(VIEW_STAGE_ARGS) {
  VIEW_STAGE_SCENARIO;
  (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)objects, (void)alpha,
      (void)raw;
  ir_surface_view(i, scenario_index(indices, L.first_lo, L.first_hi, i), &L, atlas, bases, subject, records, field,
                  out, phys, scratch, false);
  const int pixels = L.width * L.height;
  global const preal* T = (global const preal*)field + (size_t)i * pixels;
  global uchar* o = out + (size_t)i * pixels;
  const preal sd = ir_netd_of(phys, seed, index);
  if (sd > 0)
    ir_noisy_window(T, o, phys, pixels, sd, seed, index, L.view, phys + L.tables.gauss, L.flags & PS_FLAG_FAST_DRAWS);
  else
    ir_window(T, o, phys, 0, pixels);
}
