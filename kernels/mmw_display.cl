// Stage "mmw_display" (physics model): the raw grid interpolated bilinearly to the view's
// pixels (raw pixel centres at (c + 1/2) W / raw_width, edges held), then the display
// window [min, max] kelvin mapped to gray 0..255, rounded half up and clamped.
// Coordinates are held at or above 0, where truncation is floor. fp32 builds take 16
// pixels at a time in vector types (PoCL left the scalar loop unvectorised: 20x slower).
inline preal raw_coordinate(int x, preal step, int raw) {
  return fmin(fmax(((preal)x + (preal)0.5) * step - (preal)0.5, (preal)0), (preal)(raw - 1));
}

// Kelvin t through the launch's display window to a level 0..255, rounded half up, clamped.
inline uchar window_level(preal t, global const param* phys) {
  const preal lo = (preal)phys[PS_PHYS_WINDOW_MIN];
  const preal scale = (preal)255 / ((preal)phys[PS_PHYS_WINDOW_MAX] - lo);
  return (uchar)clamp(floor((t - lo) * scale + (preal)0.5), (preal)0, (preal)255);
}

kernel void stage_mmw_display(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  const int RW = L.raw_width, RH = L.raw_height;
  global const preal* grid = (global const preal*)raw + (size_t)i * RH * RW;
  const preal v = raw_coordinate(y, (preal)RH / (preal)L.height, RH);
  const int j0 = (int)v, j1 = min(j0 + 1, RH - 1);
  const preal ty = v - (preal)j0;
  global const preal* top = grid + j0 * RW;
  global const preal* bottom = grid + j1 * RW;
  const preal step = (preal)RW / (preal)L.width;
  int x = 0;
#if !defined(PRECISION_FP64)
  const float lo = (float)phys[PS_PHYS_WINDOW_MIN];
  const float scale = 255.0f / ((float)phys[PS_PHYS_WINDOW_MAX] - lo);
  // Each raw column c adds its row value times its hat max(0, 1 - |u - c|) to the pixels
  // it reaches: the bilinear weights, no gathers. A run of 16 pixels meets the columns
  // from floor(u) of its first to floor(u) + 1 of its last.
  const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  for (; x + 16 <= L.width; x += 16) {
    const float16 u = fmin(fmax(((float)x + lane + 0.5f) * step - 0.5f, 0.0f), (float)(RW - 1));
    const int c0 = (int)u.s0, c1 = min((int)u.sf + 1, RW - 1);
    float16 t = 0.0f;
    for (int c = c0; c <= c1; ++c) {
      const float value = top[c] + ty * (bottom[c] - top[c]);
      t += value * fmax(1.0f - fabs(u - (float)c), 0.0f);
    }
    const float16 gray = (t - lo) * scale + 0.5f;
    store16(convert_uchar16(convert_int16(fmin(fmax(gray, 0.0f), 255.0f))), out + row0 + x);
  }
#endif
  for (; x < L.width; ++x) {
    const preal u = raw_coordinate(x, step, RW);
    const int i0 = (int)u, i1 = min(i0 + 1, RW - 1);
    const preal tx = u - (preal)i0;
    const preal t0 = top[i0] + tx * (top[i1] - top[i0]);
    const preal t1 = bottom[i0] + tx * (bottom[i1] - bottom[i0]);
    out[row0 + x] = window_level(t0 + ty * (t1 - t0), phys);
  }
}
