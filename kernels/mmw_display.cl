// Stage "mmw_display" (physics model): the raw grid interpolated to the view's pixels, then
// the display window [min, max] kelvin mapped to gray 0..255, rounded half up and clamped.
// The interpolation (bilinear or bicubic, raw pixel centres at (c + 1/2) W / raw_width,
// edges held) and any Gaussian smoothing after it are linear and separable, so the host
// gives them as weight tables (L.tables.display: dx, dy and their bands, derived once per
// launch from the knobs): view pixel (x, y) is sum_r dy[y][r] sum_c dx[c][x] raw[r][c]. One
// work-item per scenario draws the whole view.

#if !defined(PRECISION_FP64)
// The 16 view columns x0 .. x0 + 15 of a view row whose vertically weighted raw values are
// r: each raw column of [lo, hi] against its 16 weights, in column order. A column whose
// weight is zero for a pixel adds +-0 to its sum, which leaves it as it is, so a pixel's
// value is the sum over its own columns whatever band covers them.
inline float16 mmw_run(global const float* restrict r, global const param* dx, int lo, int hi, int stride, int x0) {
  float16 t = 0.0f;
  for (int c = lo; c <= hi; ++c) t += r[c] * LOADF16(global, dx + c * stride + x0);
  return t;
}

// Runs of 16 view columns whose bands have at most K columns, on view rows [y0, y1): run
// m (of N, 1 or 4, side by side from x0) takes the K columns from lo[m] (its band,
// widened by columns of weight zero), their weights held in registers for all the rows;
// four runs make one store of 64 levels. K = 5 holds bilinear bands (a run's 16 pixels
// span up to 2.1 raw pixels at 200 from 28), K = 8 bicubic ones.
#define MMW_RUNS_K(K, N)                                                                                            \
  inline void mmw_runs_##K##x##N(global const float* restrict rows, global uchar* restrict o,                       \
                                 global const param* dx, const int* lo, int stride, int x0, int y0, int y1, int W, \
                                 int RW, float wlo, float scale) {                                                 \
    float16 w[N][K];                                                                                                \
    _Pragma("unroll") for (int m = 0; m < N; ++m) _Pragma("unroll") for (int k = 0; k < K; ++k) w[m][k] =          \
        LOADF16(global, dx + (lo[m] + k) * stride + x0 + 16 * m);                                                   \
    global const float* restrict r = rows + (size_t)y0 * RW;                                                        \
    global uchar* ob = o + (size_t)y0 * W + x0;                                                                     \
    for (int y = y0; y < y1; ++y, r += RW, ob += W) {                                                               \
      uchar16 l[N];                                                                                                 \
      _Pragma("unroll") for (int m = 0; m < N; ++m) {                                                               \
        global const float* rc = r + lo[m];                                                                         \
        float16 t = 0.0f;                                                                                           \
        _Pragma("unroll") for (int k = 0; k < K; ++k) t += rc[k] * w[m][k];                                         \
        l[m] = window_level16(t, wlo, scale);                                                                      \
      }                                                                                                             \
      MMW_STORE##N(l, ob);                                                                                          \
    }                                                                                                               \
  }
#define MMW_STORE4(l, ob) store64(l[0], l[1], l[2], l[3], ob)
#define MMW_STORE1(l, ob) store16(l[0], ob)
MMW_RUNS_K(5, 4)
MMW_RUNS_K(5, 1)
MMW_RUNS_K(8, 4)
MMW_RUNS_K(8, 1)

// Runs of 16 view columns from x0 on view rows [y0, y1), run m over raw columns
// [lo[m], hi[m]]: mmw_runs_K where every band has at most 8 columns, else column by column.
inline void mmw_runs(global const float* restrict rows, global uchar* restrict o, global const param* dx,
                     const int* lo, const int* hi, int count, int stride, int x0, int y0, int y1, int W, int RW,
                     float wlo, float scale) {
  int widest = 0;
  for (int m = 0; m < count; ++m) widest = max(widest, hi[m] - lo[m] + 1);
  const int K = widest <= 5 ? 5 : 8;
  if (widest <= 8 && RW >= K) {
    int from[4];
    for (int m = 0; m < count; ++m) from[m] = min(lo[m], RW - K);
    if (K == 5 && count == 4)
      mmw_runs_5x4(rows, o, dx, from, stride, x0, y0, y1, W, RW, wlo, scale);
    else if (K == 5)
      mmw_runs_5x1(rows, o, dx, from, stride, x0, y0, y1, W, RW, wlo, scale);
    else if (count == 4)
      mmw_runs_8x4(rows, o, dx, from, stride, x0, y0, y1, W, RW, wlo, scale);
    else
      mmw_runs_8x1(rows, o, dx, from, stride, x0, y0, y1, W, RW, wlo, scale);
    return;
  }
  global const float* restrict r = rows + (size_t)y0 * RW;
  global uchar* ob = o + (size_t)y0 * W + x0;
  for (int y = y0; y < y1; ++y, r += RW, ob += W) {
    uchar16 l[4];
    for (int m = 0; m < count; ++m)
      l[m] = window_level16(mmw_run(r, dx, lo[m], hi[m], stride, x0 + 16 * m), wlo, scale);
    if (count == 4)
      store64(l[0], l[1], l[2], l[3], ob);
    else
      store16(l[0], ob);
  }
}
#endif

#if defined(PRECISION_FIXED)
// The fast tier's display: the same linear map taken the other way round, each raw row
// through the column weights first (RH rows, not H), with the window folded in: the display
// weights of a view row sum to 1, so the window's offset and gain go on the raw rows, and
// each view pixel is then its band of interpolated raw rows times their weights (two at
// 200 from 28, bilinear), floored and clamped. The same sum in another order: the floats
// round apart, a pixel near x.5 may round the other way (tolerance.h).
inline uchar16 level16_fast(float16 t) { return convert_uchar16(convert_int16(fmin(fmax(t, 0.0f), 255.0f))); }

inline void mmw_display_fast(global const float* restrict grid, global float* restrict hr, global uchar* restrict o,
                             global const param* phys, const PsViewLaunch* L) {
  const int W = L->width, H = L->height, RW = L->raw_width, RH = L->raw_height, stride = L->tables.display.stride;
  global const param* dx = phys + L->tables.display.dx;
  global const param* dxband = phys + L->tables.display.dxband;
  global const param* dy = phys + L->tables.display.dy;
  global const param* dyband = phys + L->tables.display.dyband;
  const float lo = (float)phys_common(phys)->window_min;
  const float scale = 255.0f / ((float)phys_common(phys)->window_max - lo);
  const int runs = stride / 16;
  for (int b = 0; b < runs; ++b) {
    const int c_lo = (int)dxband[2 * b], c_hi = (int)dxband[2 * b + 1];
    if (c_hi - c_lo < 5 && RW >= 5) {
      // Five columns (the band widened by columns of weight zero), weights in registers.
      const int c0 = min(c_lo, RW - 5);
      float16 w[5];
#pragma unroll
      for (int k = 0; k < 5; ++k) w[k] = LOADF16(global, dx + (c0 + k) * stride + 16 * b);
      for (int j = 0; j < RH; ++j) {
        global const float* g = grid + j * RW + c0;
        float16 t = g[0] * w[0];
#pragma unroll
        for (int k = 1; k < 5; ++k) t = fma((float16)g[k], w[k], t);
        STOREF16(global, fma(t - lo, (float16)scale, 0.5f), hr + j * stride + 16 * b);
      }
      continue;
    }
    for (int j = 0; j < RH; ++j) {
      global const float* g = grid + j * RW;
      float16 t = 0.0f;
      for (int c = c_lo; c <= c_hi; ++c) t = fma((float16)g[c], LOADF16(global, dx + c * stride + 16 * b), t);
      STOREF16(global, fma(t - lo, (float16)scale, 0.5f), hr + j * stride + 16 * b);
    }
  }
  const int whole = W / 16;
  for (int y = 0; y < H; ++y) {
    const int j0 = (int)dyband[2 * y], j1 = (int)dyband[2 * y + 1];
    global const param* w = dy + (size_t)y * RH;
    global uchar* oy = o + (size_t)y * W;
    int b = 0;
    if (j1 - j0 == 1) {
      // Two raw rows (bilinear between raw row centres).
      const float w0 = (float)w[j0], w1 = (float)w[j1];
      global const float* h0 = hr + j0 * stride;
      global const float* h1 = hr + j1 * stride;
      for (; b + 4 <= whole; b += 4) {
        uchar16 l[4];
#pragma unroll
        for (int m = 0; m < 4; ++m) {
          const int x = 16 * (b + m);
          l[m] = level16_fast(fma((float16)w1, LOADF16(global, h1 + x), w0 * LOADF16(global, h0 + x)));
        }
        store64(l[0], l[1], l[2], l[3], oy + 16 * b);
      }
    }
    for (; b + 4 <= whole; b += 4) {
      float16 t[4] = {0.0f, 0.0f, 0.0f, 0.0f};
      for (int j = j0; j <= j1; ++j) {
        const float wj = (float)w[j];
#pragma unroll
        for (int m = 0; m < 4; ++m) t[m] = fma((float16)wj, LOADF16(global, hr + j * stride + 16 * (b + m)), t[m]);
      }
      store64(level16_fast(t[0]), level16_fast(t[1]), level16_fast(t[2]), level16_fast(t[3]), oy + 16 * b);
    }
    // Single runs, then the last W % 16 pixels: a run ending at the view's edge over
    // pixels already made (the same values), or lane by lane in views under 16 wide.
    for (; b <= whole; ++b) {
      const int x0 = b < whole ? 16 * b : W >= 16 ? W - 16 : 0;
      if (b == whole && x0 + 16 == 16 * whole && W >= 16) break;
      float16 t = 0.0f;
      for (int j = j0; j <= j1; ++j) t = fma((float16)(float)w[j], LOADF16(global, hr + j * stride + x0), t);
      if (W >= 16) {
        store16(level16_fast(t), oy + x0);
      } else {
        uchar l[16];
        vstore16(level16_fast(t), 0, l);
        for (int k = 0; k < W; ++k) oy[k] = l[k];
      }
    }
  }
}
#endif

kernel void stage_mmw_display(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)atlas, (void)bases, (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)subject,
      (void)objects, (void)alpha, (void)records, (void)field;
  const int W = L.width, H = L.height, RW = L.raw_width, RH = L.raw_height, stride = L.tables.display.stride;
  global const preal* grid = (global const preal*)raw + (size_t)i * RH * RW;
  global uchar* o = out + (size_t)i * H * W;
  global const param* dx = phys + L.tables.display.dx;
  global const param* dxband = phys + L.tables.display.dxband;
  global const param* dy = phys + L.tables.display.dy;
  global const param* dyband = phys + L.tables.display.dyband;
  // Scratch (host: mmw_display_scratch): each view row's raw values weighted along y,
  // H x RW, 32 values of room, then (fp32, raw rows of at most 32) the raw grid in rows of 32.
  global preal* restrict rows = (global preal*)scratch + (size_t)i * PS_MMW_DISPLAY_SCRATCH(W, H, RW, RH);
#if defined(PRECISION_FIXED)
  mmw_display_fast(grid, rows, o, phys, &L);
  (void)dx, (void)dxband, (void)dy, (void)dyband, (void)stride;
#else
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
  const preal lo = (preal)phys_common(phys)->window_min;
  const preal scale = (preal)255 / ((preal)phys_common(phys)->window_max - lo);
  for (int y = 0; y < H; ++y) {
    global const preal* r = rows + (size_t)y * RW;
    for (int x = 0; x < W; ++x) {
      const int b = x / 16;
      preal t = 0;
      for (int c = (int)dxband[2 * b]; c <= (int)dxband[2 * b + 1]; ++c) t += r[c] * (preal)dx[c * stride + x];
      o[(size_t)y * W + x] = window_level(t, lo, scale);
    }
  }
#else
  const float lo = (float)phys_common(phys)->window_min;
  const float scale = 255.0f / ((float)phys_common(phys)->window_max - lo);
  // Bands of 32 view rows (6 KB of levels at 200 pixels a row, which stay in the L1
  // cache while each run is stored): four whole runs (64 pixels, one store64) at a time,
  // then single runs, then the last W % 16 pixels as one run ending at the view's edge
  // (over pixels already made, which it makes again alike). Views under 16 pixels wide
  // lane by lane.
  const int runs = W / 16;
  global const float* restrict r = rows;
  if (runs > 0) {
    for (int y0 = 0; y0 < H; y0 += 32) {
      const int y1 = min(y0 + 32, H);
      int lo4[4], hi4[4], b = 0;
      for (; b + 4 <= runs; b += 4) {
        for (int m = 0; m < 4; ++m) lo4[m] = (int)dxband[2 * (b + m)], hi4[m] = (int)dxband[2 * (b + m) + 1];
        mmw_runs(rows, o, dx, lo4, hi4, 4, stride, 16 * b, y0, y1, W, RW, lo, scale);
      }
      for (; b < runs; ++b) {
        lo4[0] = (int)dxband[2 * b], hi4[0] = (int)dxband[2 * b + 1];
        mmw_runs(rows, o, dx, lo4, hi4, 1, stride, 16 * b, y0, y1, W, RW, lo, scale);
      }
      if (16 * runs == W) continue;
      lo4[0] = (int)dxband[2 * (runs - 1)], hi4[0] = (int)dxband[2 * runs + 1];
      mmw_runs(rows, o, dx, lo4, hi4, 1, stride, W - 16, y0, y1, W, RW, lo, scale);
    }
    return;
  }
  global uchar* ob = o;
  for (int y = 0; y < H; ++y, r += RW, ob += W) {
    uchar l[16];
    vstore16(window_level16(mmw_run(r, dx, (int)dxband[0], (int)dxband[1], stride, 0), lo, scale), 0, l);
    for (int k = 0; k < W; ++k) ob[k] = l[k];
  }
#endif
#endif
}
