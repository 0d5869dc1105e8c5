// Stage "sample" (physics model): each raw pixel of the MMW camera integrates the blurred
// field over its footprint, W / raw_width by H / raw_height view pixels, with partial
// pixels weighted by the area they share. One work-item per (scenario, raw row).
kernel void stage_sample(VIEW_STAGE_ARGS) {
  RAW_STAGE_ROW;
  const int W = L.width, H = L.height, RW = L.raw_width, RH = L.raw_height;
  global const preal* f = (global const preal*)field + (size_t)i * H * W;
  const preal fy0 = (preal)(j * H) / (preal)RH, fy1 = (preal)((j + 1) * H) / (preal)RH;
  const int y0 = (j * H) / RH, y1 = min(H, ((j + 1) * H + RH - 1) / RH);
  for (int c = 0; c < RW; ++c) r[c] = 0;
  for (int y = y0; y < y1; ++y) {
    const preal wy = fmin((preal)(y + 1), fy1) - fmax((preal)y, fy0);
    global const preal* row = f + (size_t)y * W;
    for (int c = 0; c < RW; ++c) {
      const preal fx0 = (preal)(c * W) / (preal)RW, fx1 = (preal)((c + 1) * W) / (preal)RW;
      const int x0 = (c * W) / RW, x1 = min(W, ((c + 1) * W + RW - 1) / RW);
      preal acc = 0;
      for (int x = x0; x < x1; ++x) acc += (fmin((preal)(x + 1), fx1) - fmax((preal)x, fx0)) * row[x];
      r[c] += wy * acc;
    }
  }
  const preal area = ((preal)W / (preal)RW) * ((preal)H / (preal)RH);
  for (int c = 0; c < RW; ++c) r[c] /= area;
}
