// Stage "mmw_display" (physics model): the raw grid interpolated to the view's pixels, then
// the display window [min, max] kelvin mapped to gray 0..255, rounded half up and clamped.
// The interpolation (bilinear or bicubic, raw pixel centres at (c + 1/2) W / raw_width,
// edges held) and any Gaussian smoothing after it are linear and separable, so the host
// gives them as weight tables (L.phys_dx, L.phys_dy and their bands: derived once per
// launch from the knobs): view pixel (x, y) is sum_r dy[y][r] sum_c dx[c][x] raw[r][c]. One
// work-item per scenario draws the whole view.

// Kelvin t through the launch's display window to a level 0..255, rounded half up, clamped.
inline uchar window_level(preal t, global const param* phys) {
  const preal lo = (preal)phys[PS_PHYS_WINDOW_MIN];
  const preal scale = (preal)255 / ((preal)phys[PS_PHYS_WINDOW_MAX] - lo);
  return (uchar)clamp(floor((t - lo) * scale + (preal)0.5), (preal)0, (preal)255);
}

#if !defined(PRECISION_FP64)
// window_level on 16 values, lo and scale as window_level has them: clamped before the
// truncation, which is then floor.
inline uchar16 window_levels16(float16 t, float lo, float scale) {
  return convert_uchar16(convert_int16(fmin(fmax((t - lo) * scale + 0.5f, 0.0f), 255.0f)));
}

// Run b's 16 view columns on a view row whose vertically weighted raw values are r: each
// raw column of the run's band against its 16 weights.
inline float16 mmw_run(global const float* restrict r, global const param* dx, global const param* band, int stride,
                       int b) {
  float16 t = 0.0f;
  for (int c = (int)band[2 * b]; c <= (int)band[2 * b + 1]; ++c) t += r[c] * LOADF16(global, dx + c * stride + 16 * b);
  return t;
}
#endif

kernel void stage_mmw_display(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)atlas, (void)bases, (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)subject,
      (void)objects, (void)alpha, (void)sigma, (void)records, (void)field;
  const int W = L.width, H = L.height, RW = L.raw_width, RH = L.raw_height, stride = L.display_stride;
  global const preal* grid = (global const preal*)raw + (size_t)i * RH * RW;
  global uchar* o = out + (size_t)i * H * W;
  global const param* dx = phys + L.phys_dx;
  global const param* dxband = phys + L.phys_dxband;
  global const param* dy = phys + L.phys_dy;
  global const param* dyband = phys + L.phys_dyband;
  // Scratch (host: mmw_display_scratch): each view row's raw values weighted along y, H x RW.
  global preal* restrict rows = (global preal*)scratch + (size_t)i * ((size_t)H * RW + 16 * (size_t)RH);
  for (int y = 0; y < H; ++y) {
    global preal* restrict r = rows + (size_t)y * RW;
    for (int c = 0; c < RW; ++c) r[c] = 0;
    for (int j = (int)dyband[2 * y]; j <= (int)dyband[2 * y + 1]; ++j) {
      const preal w = (preal)dy[(size_t)y * RH + j];
      global const preal* restrict g = grid + j * RW;
      for (int c = 0; c < RW; ++c) r[c] += w * g[c];
    }
  }
#if defined(PRECISION_FP64)
  for (int y = 0; y < H; ++y) {
    global const preal* r = rows + (size_t)y * RW;
    for (int x = 0; x < W; ++x) {
      const int b = x / 16;
      preal t = 0;
      for (int c = (int)dxband[2 * b]; c <= (int)dxband[2 * b + 1]; ++c) t += r[c] * (preal)dx[c * stride + x];
      o[(size_t)y * W + x] = window_level(t, phys);
    }
  }
#else
  const float lo = (float)phys[PS_PHYS_WINDOW_MIN];
  const float scale = 255.0f / ((float)phys[PS_PHYS_WINDOW_MAX] - lo);
  // Four whole runs (64 pixels, one store64) at a time down the view, then single runs,
  // then the last W % 16 pixels lane by lane.
  const int runs = W / 16;
  int b = 0;
  for (; b + 4 <= runs; b += 4) {
    global const float* restrict r = rows;
    global uchar* ob = o + 16 * b;
    for (int y = 0; y < H; ++y, r += RW, ob += W)
      store64(window_levels16(mmw_run(r, dx, dxband, stride, b), lo, scale),
              window_levels16(mmw_run(r, dx, dxband, stride, b + 1), lo, scale),
              window_levels16(mmw_run(r, dx, dxband, stride, b + 2), lo, scale),
              window_levels16(mmw_run(r, dx, dxband, stride, b + 3), lo, scale), ob);
  }
  for (; b < runs; ++b) {
    global const float* restrict r = rows;
    global uchar* ob = o + 16 * b;
    for (int y = 0; y < H; ++y, r += RW, ob += W) store16(window_levels16(mmw_run(r, dx, dxband, stride, b), lo, scale), ob);
  }
  if (16 * runs == W) return;
  global const float* restrict r = rows;
  global uchar* ob = o + 16 * runs;
  for (int y = 0; y < H; ++y, r += RW, ob += W) {
    uchar l[16];
    vstore16(window_levels16(mmw_run(r, dx, dxband, stride, runs), lo, scale), 0, l);
    for (int k = 0; k < W - 16 * runs; ++k) ob[k] = l[k];
  }
#endif
}
