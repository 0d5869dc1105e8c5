// Stage "netd" (physics model): the MMW camera's sensor noise over L.frames raw frames
// averaged, each frame's draw Gaussian with the NETD as standard deviation (kelvin): one
// table Gaussian per raw pixel and frame from the counter generator (frame 0 from
// PS_STREAM_RAW_NOISE, frame k from PS_STREAM_FRAME_NOISE + k; PS_GAUSS_ELEMENT;
// kernels/lib/gauss.cl). Under the fast approximation the host passes one frame of
// NETD / sqrt(frames).

kernel void stage_netd(VIEW_STAGE_ARGS) {
  RAW_STAGE_ROW;
  int frames;
  const preal sd = mmw_noise_of(phys, L.frames, seed, index, &frames);
  if (sd <= 0) return;
  const bool fast = L.flags & PS_FLAG_FAST_DRAWS;
  for (int k = 0; k < frames; ++k)
    for (int c = 0; c < L.raw_width; ++c)
      r[c] += sd * (fast ? ih_cell(seed, index, frame_stream(k), L.view, j * L.raw_width + c)
                         : gauss_cell(seed, index, frame_stream(k), L.view, j * L.raw_width + c, phys + L.tables.gauss));
}
