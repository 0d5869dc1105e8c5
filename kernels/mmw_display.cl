// Stage "mmw_display" (physics model): the raw grid interpolated bilinearly to the view's
// pixels (raw pixel centres at (c + 1/2) W / raw_width, edges held), then the display
// window [min, max] kelvin mapped to gray 0..255, rounded half up and clamped.
inline preal raw_coordinate(int x, int size, int raw) {
  return clamp(((preal)x + (preal)0.5) * (preal)raw / (preal)size - (preal)0.5, (preal)0, (preal)(raw - 1));
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
  const preal v = raw_coordinate(y, L.height, RH);
  const int j0 = (int)floor(v), j1 = min(j0 + 1, RH - 1);
  const preal ty = v - (preal)j0;
  for (int x = 0; x < L.width; ++x) {
    const preal u = raw_coordinate(x, L.width, RW);
    const int i0 = (int)floor(u), i1 = min(i0 + 1, RW - 1);
    const preal tx = u - (preal)i0;
    const preal top = ((preal)1 - tx) * grid[j0 * RW + i0] + tx * grid[j0 * RW + i1];
    const preal bottom = ((preal)1 - tx) * grid[j1 * RW + i0] + tx * grid[j1 * RW + i1];
    const preal t = ((preal)1 - ty) * top + ty * bottom;
    out[row0 + x] = window_level(t, phys);
  }
}
