// Declared fast path: the thesis chain of one camera view (composite -> pattern_noise ->
// sensor_noise -> display) fused into one kernel, one work-item per (scenario, image
// row). Tested bit for bit against the chain of stage kernels and within the tiers'
// tolerances against the chain of reference stages.

kernel void render_view(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  (void)field;
  const int W = L.width;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  global uchar* row = out + row0;

  Layers Ly;
  composite_layers(&Ly, objs, sprites, places, &L, y, seed, index);

  Tiles T;
  T.count = 0;
  float gain = 0.0f;
  if (L.flags & PS_FLAG_PATTERN_NOISE) {
    const int tile_offset = noise_pattern(noise_offsets, noise_gains, &L, seed, index, &gain);
    noise_tiles(&T, objs, sprites, places, &L, tile_offset, y);
  }
  const int tile_size = L.tile_size;

  // Only the span that layers and tiles cover needs per-pixel work (all of it under
  // pixel noise); the rest of the row is the base, copied 16 bytes at a time.
  int x0 = W, x1 = 0;
  for (int k = 0; k < Ly.count; ++k) {
    x0 = min(x0, Ly.x0[k]);
    x1 = max(x1, Ly.x0[k] + Ly.width[k]);
  }
  for (int k = 0; k < T.count; ++k) {
    x0 = min(x0, T.x0[k]);
    x1 = max(x1, T.x0[k] + tile_size);
  }
  if (L.flags & PS_FLAG_PIXEL_NOISE) {
    x0 = 0;
    x1 = W;
  }
  x0 = clamp(x0, 0, W);
  x1 = clamp(x1, x0, W);
  int x = 0;
  for (; x + 16 <= x0; x += 16) vstore16(vload16(0, base + x), 0, row + x);
  for (; x < x0; ++x) row[x] = base[x];
  if (L.flags & PS_FLAG_PIXEL_NOISE) {
    // The whole row, a Box-Muller pair (one Philox draw) per two pixels, no branch per
    // pixel. Pairs follow the pixel index y*W + x, so an odd W starts rows mid-pair.
    const int p0 = y * W;
    for (; x < W; ++x) {
      const int p = p0 + x;
      const greal2 g = gauss_pair(seed, index, L.view, p >> 1);
      real v = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
      v = pattern_noise(&T, atlas, tile_size, gain, v, x);
      row[x] = to_pixel(add_gauss(v, sigma, (p & 1) ? g.y : g.x));
      if ((p & 1) == 0 && x + 1 < W) {
        ++x;
        real v1 = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
        v1 = pattern_noise(&T, atlas, tile_size, gain, v1, x);
        row[x] = to_pixel(add_gauss(v1, sigma, g.y));
      }
    }
    return;
  }
  for (; x < x1; ++x) {
    real v = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
    row[x] = to_pixel(pattern_noise(&T, atlas, tile_size, gain, v, x));
  }
  for (; x + 16 <= W; x += 16) vstore16(vload16(0, base + x), 0, row + x);
  for (; x < W; ++x) row[x] = base[x];
}
