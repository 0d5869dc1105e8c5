// Stage "netd" (physics model): the MMW camera's sensor noise, Gaussian with the NETD as
// standard deviation (kelvin), one table Gaussian per raw pixel from the counter generator
// (PS_STREAM_RAW_NOISE, PS_GAUSS_ELEMENT; kernels/sensor_noise.cl).
kernel void stage_netd(VIEW_STAGE_ARGS) {
  RAW_STAGE_ROW;
  const preal sd = (preal)phys[PS_PHYS_NETD];
  if (sd <= 0) return;
  for (int c = 0; c < L.raw_width; ++c)
    r[c] += sd * gauss_cell(seed, index, PS_STREAM_RAW_NOISE, L.view, j * L.raw_width + c, phys + L.phys_gauss);
}
