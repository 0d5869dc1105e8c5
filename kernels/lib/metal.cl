// Helpers (kernels/lib/): the metal detector's noise knob (metal, metal_physics).

// The scenario's detector noise (the knob metal_noise): noise_lo, or where the knob is
// drawn per scenario (noise_hi > noise_lo), noise_lo + below(word 0, noise_hi - noise_lo + 1)
// of PS_STREAM_KNOB_DRAW (host: drawn_knob_at).
inline int metal_noise_of(uint2 seed, ulong index, int noise_lo, int noise_hi) {
  return knob_draw(noise_lo, noise_hi, seed, index, PS_DRAWN_METAL_NOISE);
}
