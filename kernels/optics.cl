// Stage "optics" (physics model): the camera's diffraction-limited point-spread function,
// a Gaussian of the Airy core's FWHM (1.02 lambda / D), normalised over 2 R + 1 taps and
// applied along rows (field -> scratch), then along columns (scratch -> field). Pixels
// past the view's edge repeat the edge.

// Each pixel's sum runs over the taps in the same order whatever the loop shape: the
// loops over x are the inner ones, on restrict pointers, so that LLVM vectorises them
// (PoCL's vectorisation across work-items cannot reach past an inner loop). Rows: the
// interior, where no tap leaves the row, apart from the clamped edges.
kernel void stage_optics_rows(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const preal* restrict src = (global const preal*)field + row0;
  global preal* restrict dst = (global preal*)scratch + row0;
  global const param* taps = psf_taps(phys, &L);
  const int R = L.tables.psf_radius, W = L.width;
  const int lo = min(R, W), hi = max(lo, W - R);
  for (int x = 0; x < W; ++x) dst[x] = 0;
  for (int d = -R; d <= R; ++d) {
    const preal w = (preal)taps[d];
    for (int x = 0; x < lo; ++x) dst[x] += w * src[clamp(x + d, 0, W - 1)];
    for (int x = lo; x < hi; ++x) dst[x] += w * src[x + d];
    for (int x = hi; x < W; ++x) dst[x] += w * src[clamp(x + d, 0, W - 1)];
  }
}

kernel void stage_optics_columns(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const preal* restrict src = (global const preal*)scratch + (size_t)i * L.height * L.width;
  global preal* restrict dst = (global preal*)field + row0;
  global const param* taps = psf_taps(phys, &L);
  const int R = L.tables.psf_radius, W = L.width;
  for (int x = 0; x < W; ++x) dst[x] = 0;
  for (int d = -R; d <= R; ++d) {
    const preal w = (preal)taps[d];
    global const preal* restrict row = src + (size_t)clamp(y + d, 0, L.height - 1) * W;
    for (int x = 0; x < W; ++x) dst[x] += w * row[x];
  }
}
