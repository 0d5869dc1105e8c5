// Helpers (kernels/lib/): the metal detector's noise knob (metal, metal_physics).

// The scenario's detector noise (the knob metal_noise; host: drawn_knob_at), from the run's
// drawn ranges (PsPhys::drawn): the knob's, or where drawn per scenario its draw.
inline int metal_noise_of(global const param* drawn, uint2 seed, ulong index) {
  return drawn_whole(phys_drawn(drawn), PS_DRAWN_METAL_NOISE, seed, index);
}
