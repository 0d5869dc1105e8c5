// Stage "mmw_display" (physics model): the raw grid interpolated bilinearly to the view's
// pixels (raw pixel centres at (c + 1/2) W / raw_width, edges held), then the display
// window [min, max] kelvin mapped to gray 0..255, rounded half up and clamped.
// Coordinates are held at or above 0, where truncation is floor. One work-item per
// scenario draws the whole view, so what depends on x alone is worked out once per view.
inline preal raw_coordinate(int x, preal step, int raw) {
  return fmin(fmax(((preal)x + (preal)0.5) * step - (preal)0.5, (preal)0), (preal)(raw - 1));
}

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

// A run of 16 pixels from x: the raw columns it meets (from floor(u) of its first pixel to
// floor(u) + 1 of its last; at most 18, as the raw grid is never finer than the view,
// plan.cpp) and each column's hat max(0, 1 - |u - c|) over the run: the bilinear weights
// along x, the same on every row.
#define MMW_RUN_COLUMNS 18
typedef struct {
  int c0, columns;
  float16 hat[MMW_RUN_COLUMNS];
} MmwRun;

inline void mmw_run(MmwRun* R, int x, float xstep, int RW) {
  const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const float16 u = fmin(fmax(((float)x + lane + 0.5f) * xstep - 0.5f, 0.0f), (float)(RW - 1));
  R->c0 = (int)u.s0;
  R->columns = min((int)u.sf + 1, RW - 1) - R->c0 + 1;
  for (int k = 0; k < R->columns; ++k) R->hat[k] = fmax(1.0f - fabs(u - (float)(R->c0 + k)), 0.0f);
}

// The run's levels on a view row whose vertically interpolated raw values are r.
inline uchar16 mmw_run_levels(const MmwRun* R, global const float* restrict r, float lo, float scale) {
  float16 t = 0.0f;
  for (int k = 0; k < R->columns; ++k) t += r[R->c0 + k] * R->hat[k];
  return window_levels16(t, lo, scale);
}
#endif

kernel void stage_mmw_display(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)atlas, (void)bases, (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)subject,
      (void)objects, (void)alpha, (void)sigma, (void)records, (void)field;
  const int W = L.width, H = L.height, RW = L.raw_width, RH = L.raw_height;
  global const preal* grid = (global const preal*)raw + (size_t)i * RH * RW;
  global uchar* o = out + (size_t)i * H * W;
  const preal xstep = (preal)RW / (preal)W, ystep = (preal)RH / (preal)H;
#if defined(PRECISION_FP64)
  (void)scratch;
  for (int y = 0; y < H; ++y) {
    const preal v = raw_coordinate(y, ystep, RH);
    const int j0 = (int)v, j1 = min(j0 + 1, RH - 1);
    const preal ty = v - (preal)j0;
    global const preal* top = grid + j0 * RW;
    global const preal* bottom = grid + j1 * RW;
    for (int x = 0; x < W; ++x) {
      const preal u = raw_coordinate(x, xstep, RW);
      const int i0 = (int)u, i1 = min(i0 + 1, RW - 1);
      const preal tx = u - (preal)i0;
      const preal t0 = top[i0] + tx * (top[i1] - top[i0]);
      const preal t1 = bottom[i0] + tx * (bottom[i1] - bottom[i0]);
      o[(size_t)y * W + x] = window_level(t0 + ty * (t1 - t0), phys);
    }
  }
#else
  // Scratch (host: mmw_display_scratch): each view row's raw values interpolated
  // vertically, H x RW; then the last W % 16 pixels' values on each raw row, RH x 16.
  global float* restrict rows = (global float*)scratch + (size_t)i * ((size_t)H * RW + 16 * (size_t)RH);
  global float* restrict tail_rows = rows + (size_t)H * RW;
  for (int y = 0; y < H; ++y) {
    const float v = raw_coordinate(y, ystep, RH);
    const int j0 = (int)v, j1 = min(j0 + 1, RH - 1);
    const float ty = v - (float)j0;
    global const float* restrict top = grid + j0 * RW;
    global const float* restrict bottom = grid + j1 * RW;
    global float* restrict r = rows + (size_t)y * RW;
    for (int c = 0; c < RW; ++c) r[c] = top[c] + ty * (bottom[c] - top[c]);
  }
  const float lo = (float)phys[PS_PHYS_WINDOW_MIN];
  const float scale = 255.0f / ((float)phys[PS_PHYS_WINDOW_MAX] - lo);
  // Four runs (64 pixels, one store64) at a time down the view, then single runs.
  const int runs = W / 16;
  int b = 0;
  for (; b + 4 <= runs; b += 4) {
    MmwRun R[4];
    for (int q = 0; q < 4; ++q) mmw_run(&R[q], 16 * (b + q), xstep, RW);
    global const float* restrict r = rows;
    global uchar* ob = o + 16 * b;
    for (int y = 0; y < H; ++y, r += RW, ob += W)
      store64(mmw_run_levels(&R[0], r, lo, scale), mmw_run_levels(&R[1], r, lo, scale),
              mmw_run_levels(&R[2], r, lo, scale), mmw_run_levels(&R[3], r, lo, scale), ob);
  }
  for (; b < runs; ++b) {
    MmwRun R;
    mmw_run(&R, 16 * b, xstep, RW);
    global const float* restrict r = rows;
    global uchar* ob = o + 16 * b;
    for (int y = 0; y < H; ++y, r += RW, ob += W) store16(mmw_run_levels(&R, r, lo, scale), ob);
  }
  // The last W % 16 pixels interpolate along x first (their values on each raw row),
  // then along y, as the fp64 build does every pixel; 16 lanes from xt, of which those
  // before x0 keep the runs' levels.
  const int x0 = 16 * runs, xt = max(W - 16, 0);
  if (x0 == W) return;
  for (int j = 0; j < RH; ++j) {
    global const float* row = grid + j * RW;
    for (int k = 0; k < 16; ++k) {
      const float u = raw_coordinate(min(xt + k, W - 1), xstep, RW);
      const int i0 = (int)u, i1 = min(i0 + 1, RW - 1);
      const float tx = u - (float)i0;
      tail_rows[16 * j + k] = row[i0] + tx * (row[i1] - row[i0]);
    }
  }
  const char16 keep = convert_char16((int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15) < x0 - xt);
  for (int y = 0; y < H; ++y) {
    const float v = raw_coordinate(y, ystep, RH);
    const int j0 = (int)v, j1 = min(j0 + 1, RH - 1);
    const float ty = v - (float)j0;
    const float16 t0 = vload16(0, tail_rows + 16 * j0), t1 = vload16(0, tail_rows + 16 * j1);
    const uchar16 level = window_levels16(t0 + ty * (t1 - t0), lo, scale);
    global uchar* ot = o + (size_t)y * W + xt;
    if (W >= 16) {
      store16(select(level, load16(ot), keep), ot);
    } else {
      uchar l[16];
      vstore16(level, 0, l);
      for (int k = 0; k < W; ++k) ot[k] = l[k];
    }
  }
#endif
}
