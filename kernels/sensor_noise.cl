// Stage "sensor_noise": per-pixel Gaussian noise, sigma gray levels: Box-Muller pairs
// (gauss_pair), or the fast tier's Irwin-Hall draws (ih_pixel), kernels/lib/gauss.cl.
kernel void stage_sensor_noise(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  if (!(L.flags & PS_FLAG_PIXEL_NOISE)) return;
  const param sigma = pixel_sigma_of(phys, seed, index);
  const int p0 = y * L.width;
#if defined(NOISE_DRAW_IH)
  for (int x = 0; x < L.width; ++x)
    field[row0 + x] = add_gauss(field[row0 + x], sigma, ih_pixel(seed, index, L.view, p0 + x));
#else
  for (int x = 0; x < L.width; ++x) {
    const int p = p0 + x;
    const greal2 g = gauss_pair(seed, index, L.view, p >> 1);
    field[row0 + x] = add_gauss(field[row0 + x], sigma, (p & 1) ? g.y : g.x);
  }
#endif
}
