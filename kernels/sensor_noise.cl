// Stage "sensor_noise": per-pixel Gaussian noise, sigma gray levels. One Philox draw
// feeds a Box-Muller pair (pixels 2k, 2k+1 of the view), computed at the build's
// Gaussian precision.

inline greal2 gauss_pair(uint2 seed, ulong index, int view, int pair) {
  const uint4 r = draw(seed, index, PS_STREAM_PIXEL_NOISE, ((uint)view << PS_PIXEL_NOISE_VIEW_SHIFT) | (uint)pair);
  const greal u1 = (greal)1 - (greal)(r.x >> 8) * ((greal)1 / (greal)16777216);
  const greal u2 = (greal)(r.y >> 8) * ((greal)1 / (greal)16777216);
  const greal rad = sqrt((greal)-2 * log(u1));
  const greal th = (greal)6.283185307179586 * u2;
  return (greal2)(rad * cos(th), rad * sin(th));
}

kernel void stage_sensor_noise(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  if (!(L.flags & PS_FLAG_PIXEL_NOISE)) return;
  const int p0 = y * L.width;
  for (int x = 0; x < L.width; ++x) {
    const int p = p0 + x;
    const greal2 g = gauss_pair(seed, index, L.view, p >> 1);
    field[row0 + x] = add_gauss(field[row0 + x], sigma, (p & 1) ? g.y : g.x);
  }
}
