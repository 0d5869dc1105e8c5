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

// The 16 view columns x0 .. x0 + 15 of a view row whose vertically weighted raw values are
// r: each raw column of [lo, hi] against its 16 weights, in column order. A column whose
// weight is zero for a pixel adds +-0 to its sum, which leaves it as it is, so a pixel's
// value is the sum over its own columns whatever band covers them.
inline float16 mmw_run(global const float* restrict r, global const param* dx, int lo, int hi, int stride, int x0) {
  float16 t = 0.0f;
  for (int c = lo; c <= hi; ++c) t += r[c] * LOADF16(global, dx + c * stride + x0);
  return t;
}

// Four whole runs of 16 view columns from x0 down the whole view, where every run's band
// has at most four columns: each run takes the four columns from lo[m] (its band, widened
// by columns of weight zero), their weights held in registers for all the rows.
inline void mmw_runs4x4(global const float* restrict rows, global uchar* restrict o, global const param* dx,
                        const int* lo, int stride, int x0, int H, int W, int RW, float wlo, float scale) {
  float16 w[4][4];
#pragma unroll
  for (int m = 0; m < 4; ++m)
#pragma unroll
    for (int k = 0; k < 4; ++k) w[m][k] = LOADF16(global, dx + (lo[m] + k) * stride + x0 + 16 * m);
  global const float* restrict r = rows;
  global uchar* ob = o + x0;
  for (int y = 0; y < H; ++y, r += RW, ob += W) {
    uchar16 l[4];
#pragma unroll
    for (int m = 0; m < 4; ++m) {
      global const float* rc = r + lo[m];
      float16 t = 0.0f;
      t += rc[0] * w[m][0];
      t += rc[1] * w[m][1];
      t += rc[2] * w[m][2];
      t += rc[3] * w[m][3];
      l[m] = window_levels16(t, wlo, scale);
    }
    store64(l[0], l[1], l[2], l[3], ob);
  }
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
  // Scratch (host: mmw_display_scratch): each view row's raw values weighted along y,
  // H x RW, 32 values of room, then (fp32, raw rows of at most 32) the raw grid in rows of 32.
  global preal* restrict rows = (global preal*)scratch + (size_t)i * PS_MMW_DISPLAY_SCRATCH(H, RW, RH);
#if !defined(PRECISION_FP64)
  if (RW <= 32) {
    // Rows of 16 or 32 lanes: the raw grid padded to rows of 32 (zeros past RW), then each
    // view row's sum as the loop below makes it, lane by lane, stored whole in row order
    // (lanes past RW spill into the next row, whose own store follows, or the room).
    global float* restrict g = rows + (size_t)H * RW + 32;
    for (int j = 0; j < RH; ++j)
      for (int c = 0; c < 32; ++c) g[32 * j + c] = c < RW ? grid[j * RW + c] : 0.0f;
    for (int y = 0; y < H; ++y) {
      float16 a = 0.0f, b = 0.0f;
      for (int j = (int)dyband[2 * y]; j <= (int)dyband[2 * y + 1]; ++j) {
        const float w = (float)dy[(size_t)y * RH + j];
        a += w * LOADF16(global, g + 32 * j);
        b += w * LOADF16(global, g + 32 * j + 16);
      }
      STOREF16(global, a, rows + (size_t)y * RW);
      if (RW > 16) STOREF16(global, b, rows + (size_t)y * RW + 16);
    }
  } else
#endif
  {
    for (int y = 0; y < H; ++y) {
      global preal* restrict r = rows + (size_t)y * RW;
      for (int c = 0; c < RW; ++c) r[c] = 0;
      for (int j = (int)dyband[2 * y]; j <= (int)dyband[2 * y + 1]; ++j) {
        const preal w = (preal)dy[(size_t)y * RH + j];
        global const preal* restrict g = grid + j * RW;
        for (int c = 0; c < RW; ++c) r[c] += w * g[c];
      }
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
  // then the last W % 16 pixels: one run ending at the view's edge where the view has 16
  // (over pixels already made, which it makes again alike), else lane by lane.
  const int runs = W / 16;
  int b = 0;
  for (; b + 4 <= runs; b += 4) {
    int band_lo[4];
    bool narrow = RW >= 4;
    for (int m = 0; m < 4; ++m) {
      const int a = (int)dxband[2 * (b + m)], z = (int)dxband[2 * (b + m) + 1];
      narrow = narrow && z - a < 4;
      band_lo[m] = min(a, RW - 4);
    }
    if (narrow) {
      mmw_runs4x4(rows, o, dx, band_lo, stride, 16 * b, H, W, RW, lo, scale);
      continue;
    }
    global const float* restrict r = rows;
    global uchar* ob = o + 16 * b;
    for (int y = 0; y < H; ++y, r += RW, ob += W) {
      uchar16 l[4];
      for (int m = 0; m < 4; ++m)
        l[m] = window_levels16(
            mmw_run(r, dx, (int)dxband[2 * (b + m)], (int)dxband[2 * (b + m) + 1], stride, 16 * (b + m)), lo, scale);
      store64(l[0], l[1], l[2], l[3], ob);
    }
  }
  for (; b < runs; ++b) {
    global const float* restrict r = rows;
    global uchar* ob = o + 16 * b;
    const int c_lo = (int)dxband[2 * b], c_hi = (int)dxband[2 * b + 1];
    for (int y = 0; y < H; ++y, r += RW, ob += W) store16(window_levels16(mmw_run(r, dx, c_lo, c_hi, stride, 16 * b), lo, scale), ob);
  }
  if (16 * runs == W) return;
  global const float* restrict r = rows;
  if (runs > 0) {
    const int x0 = W - 16, c_lo = (int)dxband[2 * (x0 / 16)], c_hi = (int)dxband[2 * runs + 1];
    global uchar* ob = o + x0;
    for (int y = 0; y < H; ++y, r += RW, ob += W) store16(window_levels16(mmw_run(r, dx, c_lo, c_hi, stride, x0), lo, scale), ob);
    return;
  }
  global uchar* ob = o;
  for (int y = 0; y < H; ++y, r += RW, ob += W) {
    uchar l[16];
    vstore16(window_levels16(mmw_run(r, dx, (int)dxband[0], (int)dxband[1], stride, 0), lo, scale), 0, l);
    for (int k = 0; k < W; ++k) ob[k] = l[k];
  }
#endif
}
