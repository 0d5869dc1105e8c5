// Stage "netd" (physics model): the MMW camera's sensor noise over L.frames raw frames
// averaged, each frame's draw Gaussian with the NETD as standard deviation (kelvin): one
// table Gaussian per raw pixel and frame from the counter generator (frame 0 from
// PS_STREAM_RAW_NOISE, frame k from PS_STREAM_FRAME_NOISE + k; PS_GAUSS_ELEMENT;
// kernels/sensor_noise.cl). Under the fast approximation the host passes one frame of
// NETD / sqrt(frames).
inline uint frame_stream(int k) { return k == 0 ? PS_STREAM_RAW_NOISE : PS_STREAM_FRAME_NOISE + (uint)k; }

kernel void stage_netd(VIEW_STAGE_ARGS) {
  RAW_STAGE_ROW;
  const preal sd = (preal)phys[PS_PHYS_NETD] / (preal)L.frames;
  if (sd <= 0) return;
  for (int k = 0; k < L.frames; ++k)
    for (int c = 0; c < L.raw_width; ++c)
      r[c] += sd * gauss_cell(seed, index, frame_stream(k), L.view, j * L.raw_width + c, phys + L.phys_gauss);
}
