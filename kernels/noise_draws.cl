// The unit draws of a sensor model's per-pixel noise as this build makes them (`portalsim
// tradeoff`'s distribution columns): pixels [0, cells) of view 0 of scenario first + i, one
// work-item per scenario. Under NOISE_DRAW_IH (noise_draw irwin-hall) both models' draws are
// Irwin-Hall (kernels/lib/gauss.cl): the thesis pixel noise's stream, the physics MMW raw
// noise's; otherwise the thesis pixel noise is Box-Muller and the physics raw noise table
// Gaussians (table: the host's quantiles).
kernel void noise_draws(uint seed_lo, uint seed_hi, ulong first, int physics, int cells, global const param* table,
                        global float* out) {
  const size_t i = get_global_id(0);
  const uint2 seed = (uint2)(seed_lo, seed_hi);
  const ulong index = first + i;
  global float* o = out + i * (size_t)cells;
  for (int p = 0; p < cells; ++p) {
#if defined(NOISE_DRAW_IH)
    o[p] = physics ? (float)ih_cell(seed, index, PS_STREAM_RAW_NOISE, 0, p) : (float)ih_pixel(seed, index, 0, p);
#else
    if (physics) {
      o[p] = (float)gauss_cell(seed, index, PS_STREAM_RAW_NOISE, 0, p, table);
      continue;
    }
    const greal2 g = gauss_pair(seed, index, 0, p >> 1);
    o[p] = (float)((p & 1) ? g.y : g.x);
#endif
  }
}
