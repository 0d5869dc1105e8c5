// Stage "netd" (physics model): the MMW camera's sensor noise, Gaussian with the NETD as
// standard deviation (kelvin), one draw per raw pixel from the counter generator
// (PS_STREAM_RAW_NOISE; Box-Muller pairs of raw pixels 2k, 2k + 1, as sensor_noise).
kernel void stage_netd(VIEW_STAGE_ARGS) {
  RAW_STAGE_ROW;
  const preal sd = (preal)phys[PS_PHYS_NETD];
  if (sd <= 0) return;
  for (int c = 0; c < L.raw_width; ++c) {
    const int p = j * L.raw_width + c;
    const greal2 g = gauss_pair_of(seed, index, PS_STREAM_RAW_NOISE, L.view, p >> 1);
    r[c] += sd * (preal)((p & 1) ? g.y : g.x);
  }
}
