// Stage "pattern_noise" (thesis 4.2). The scenario's MMW noise pattern, chosen by the
// counter generator, is laid over every object: a square tile centred on the object's
// sprite, v += gain (tile - 128).

typedef struct {
  int count;
  int offset[PS_MAX_LAYERS];  // atlas offset of the tile row that meets this image row
  int x0[PS_MAX_LAYERS];
} Tiles;

// The scenario's pattern: its atlas offset, and its gain in *gain.
inline int noise_pattern(global const int* noise_offsets, global const float* noise_gains, const PsViewLaunch* L,
                         uint2 seed, ulong index, float* gain) {
  const uint k = below(draw(seed, index, PS_STREAM_NOISE_PATTERN, 0u).x, (uint)L->patterns);
  *gain = noise_gains[k];
  return noise_offsets[k];
}

// Collects the noise tiles of the view's regions that cross row y.
inline void noise_tiles(Tiles* T, global const short* objects, global const int4* sprites, global const int2* places,
                        const PsViewLaunch* L, int tile_offset, int y) {
  T->count = 0;
  const int tile = L->tile_size;
  for (int r = 0; r < PS_REGIONS; ++r) {
    const int v = objects[r];
    if (v < 0 || !((L->region_mask >> r) & 1u)) continue;
    const int4 sp = sprite_of(sprites, L, v);
    const int2 pl = place_of(places, L, v, r);
    const int tx0 = pl.x + (sp.y >> 1) - (tile >> 1);
    const int ty0 = pl.y + (sp.z >> 1) - (tile >> 1);
    if (y < ty0 || y >= ty0 + tile) continue;
    const int k = T->count++;
    T->offset[k] = tile_offset + (y - ty0) * tile;
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

kernel void stage_pattern_noise(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  if (!(L.flags & PS_FLAG_PATTERN_NOISE)) return;
  float gain;
  const int tile_offset = noise_pattern(noise_offsets, noise_gains, &L, seed, index, &gain);
  Tiles T;
  noise_tiles(&T, objs, sprites, places, &L, tile_offset, y);
  if (T.count == 0) return;
  for (int x = 0; x < L.width; ++x) field[row0 + x] = pattern_noise(&T, atlas, L.tile_size, gain, field[row0 + x], x);
}
