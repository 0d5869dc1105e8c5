// Noise injection (thesis 4.2). The scenario's MMW noise pattern, chosen by the counter
// generator, is laid over every object: a square tile centred on the object's sprite.
// Optional per-pixel Gaussian sensor noise comes on top.

#define FLAG_PATTERN_NOISE 1
#define FLAG_PIXEL_NOISE 2

typedef struct {
  int count;
  int offset[MAX_LAYERS];  // atlas offset of the tile row that meets this image row
  int x0[MAX_LAYERS];
} Tiles;

// Collects the noise tiles of regions [r_begin, r_end) that cross row y (MMW only).
inline void noise_tiles(Tiles* T, global const short* objects, global const int4* sprites,
                        global const int4* places, int tile_offset, int tile_size, int r_begin, int r_end,
                        int y) {
  T->count = 0;
  for (int r = r_begin; r < r_end; ++r) {
    const int v = objects[r];
    if (v < 0) continue;
    const int4 sp = sprites[v * 2];
    const int4 pl = places[v * 13 + r];
    const int tx0 = pl.x + (sp.y >> 1) - (tile_size >> 1);
    const int ty0 = pl.y + (sp.z >> 1) - (tile_size >> 1);
    if (y < ty0 || y >= ty0 + tile_size) continue;
    const int k = T->count++;
    T->offset[k] = tile_offset + (y - ty0) * tile_size;
    T->x0[k] = tx0;
  }
}

// v with the pattern noise of every tile over pixel x added (tile values summed first).
inline real pattern_noise(const Tiles* T, global const uchar* atlas, int tile_size, float gain, real v, int x) {
  real n = real_zero();
  for (int k = 0; k < T->count; ++k) {
    const int tx = x - T->x0[k];
    if (tx < 0 || tx >= tile_size) continue;
    n = noise_acc(n, atlas[T->offset[k] + tx]);
  }
  return add_noise(v, gain, n);
}

// Per-pixel sensor noise: one Philox draw feeds a Box-Muller pair (pixels 2k, 2k+1),
// computed at the build's Gaussian precision.
inline greal2 gauss_pair(uint2 seed, ulong index, int view, int pair) {
  const uint4 r = draw(seed, index, STREAM_PIXEL_NOISE, ((uint)view << 28) | (uint)pair);
  const greal u1 = (greal)1 - (greal)(r.x >> 8) * ((greal)1 / (greal)16777216);
  const greal u2 = (greal)(r.y >> 8) * ((greal)1 / (greal)16777216);
  const greal rad = sqrt((greal)-2 * log(u1));
  const greal th = (greal)6.283185307179586 * u2;
  return (greal2)(rad * cos(th), rad * sin(th));
}
