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

inline float pattern_noise_pixel(const Tiles* T, global const uchar* atlas, int tile_size, float gain, int x) {
  float n = 0.0f;
  for (int k = 0; k < T->count; ++k) {
    const int tx = x - T->x0[k];
    if (tx < 0 || tx >= tile_size) continue;
    n += (float)atlas[T->offset[k] + tx] - 128.0f;
  }
  return gain * n;
}

// Per-pixel sensor noise: one Philox draw feeds a Box-Muller pair (pixels 2k, 2k+1).
inline float pixel_noise(uint2 seed, ulong index, int view, int p) {
  const uint4 r = draw(seed, index, STREAM_PIXEL_NOISE, ((uint)view << 28) | ((uint)p >> 1));
  const float2 g = gauss2(r.x, r.y);
  return (p & 1) ? g.y : g.x;
}
