// Stage "pattern_noise" (thesis 4.2). The scenario's MMW noise pattern, chosen by the
// counter generator, is laid over every object: a square tile centred on the object's
// sprite, v += gain (tile - 128).

kernel void stage_pattern_noise(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  Tiles T;
  noise_tiles(&T, rec, noise_offsets, &L, y);
  if (T.count == 0) return;
  const float gain = pattern_gain(rec, noise_gains);
  for (int x = 0; x < L.width; ++x) field[row0 + x] = pattern_noise(&T, atlas, L.tile_size, gain, field[row0 + x], x);
}
