// Stage "pattern_noise" (thesis 4.2). The scenario's MMW noise pattern, chosen by the
// counter generator, is laid over every object: a square tile centred on the object's
// sprite, v += gain (tile - 128).

typedef struct {
  int count;
  int offset[PS_MAX_LAYERS];  // atlas offset of the tile row that meets this image row
  int poff[PS_MAX_LAYERS];    // the same row of the padded copy
  int x0[PS_MAX_LAYERS];
} Tiles;

// Collects the noise tiles of the scenario's record that cross row y (none when it has
// no pattern).
inline void noise_tiles(Tiles* T, global const int* rec, global const int* noise_offsets, const PsViewLaunch* L,
                        int y) {
  T->count = 0;
  const int pattern = rec[PS_REC_PATTERN];
  if (pattern < 0) return;
  const int tile = L->tile_size;
  const int tile_offset = noise_offsets[pattern], padded_offset = noise_offsets[L->patterns + pattern];
  for (int j = 0; j < rec[PS_REC_COUNT]; ++j) {
    global const int* ly = rec + PS_REC_LAYERS + j * PS_LAYER_LEN;
    const int ty0 = ly[PS_LAYER_TILE_Y0];
    if (y < ty0 || y >= ty0 + tile) continue;
    const int k = T->count++;
    T->offset[k] = tile_offset + (y - ty0) * tile;
    T->poff[k] = padded_offset + (y - ty0) * (tile + 2 * PS_PAD);
    T->x0[k] = ly[PS_LAYER_TILE_X0];
  }
}

// The gain of the scenario's pattern (0 for none).
inline float pattern_gain(global const int* rec, global const float* noise_gains) {
  return rec[PS_REC_PATTERN] < 0 ? 0.0f : noise_gains[rec[PS_REC_PATTERN]];
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
  Tiles T;
  noise_tiles(&T, rec, noise_offsets, &L, y);
  if (T.count == 0) return;
  const float gain = pattern_gain(rec, noise_gains);
  for (int x = 0; x < L.width; ++x) field[row0 + x] = pattern_noise(&T, atlas, L.tile_size, gain, field[row0 + x], x);
}
