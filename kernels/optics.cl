// Stage "optics" (physics model): the camera's diffraction-limited point-spread function,
// a Gaussian of the Airy core's FWHM (1.02 lambda / D), normalised over 2 R + 1 taps and
// applied along rows (field -> scratch), then along columns (scratch -> field). Pixels
// past the view's edge repeat the edge.
inline global const param* psf_taps(global const param* phys, const PsViewLaunch* L) {
  return phys + PS_PHYS_TAPS(L->subjects, L->variants) + L->psf_radius;
}

kernel void stage_optics_rows(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const preal* src = (global const preal*)field + row0;
  global preal* dst = (global preal*)scratch + row0;
  global const param* taps = psf_taps(phys, &L);
  const int R = L.psf_radius, W = L.width;
  for (int x = 0; x < W; ++x) dst[x] = 0;
  for (int d = -R; d <= R; ++d) {
    const preal w = (preal)taps[d];
    for (int x = 0; x < W; ++x) dst[x] += w * src[clamp(x + d, 0, W - 1)];
  }
}

kernel void stage_optics_columns(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const preal* src = (global const preal*)scratch + (size_t)i * L.height * L.width;
  global preal* dst = (global preal*)field + row0;
  global const param* taps = psf_taps(phys, &L);
  const int R = L.psf_radius, W = L.width;
  for (int x = 0; x < W; ++x) dst[x] = 0;
  for (int d = -R; d <= R; ++d) {
    const preal w = (preal)taps[d];
    global const preal* row = src + (size_t)clamp(y + d, 0, L.height - 1) * W;
    for (int x = 0; x < W; ++x) dst[x] += w * row[x];
  }
}
