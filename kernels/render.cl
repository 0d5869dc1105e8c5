// Renders one sensor view for a batch: one work-item per (scenario, image row).
// view: 0 MMW upper (regions 1-6), 1 MMW lower (regions 7-13), 2 IR (all regions).

kernel void render_view(global const uchar* atlas, global const int* bases, global const int4* sprites,
                        global const int4* places, global const int* noise_offsets,
                        global const float* noise_gains, global const uchar* subject,
                        global const short* objects, uint n, int view, int W, int H, param alpha,
                        uint2 seed, uint2 first, int patterns, int tile_size, param sigma, int flags,
                        int placement, float jx, float jy, global uchar* out) {
  const size_t gid = get_global_id(0);
  const uint i = (uint)(gid / (size_t)H);
  const int y = (int)(gid % (size_t)H);
  if (i >= n) return;
  const ulong index = upsample(first.y, first.x) + i;
  const int sensor = view == 2 ? 1 : 0;
  const int r_begin = view == 1 ? 6 : 0;
  const int r_end = view == 0 ? 6 : 13;
  global const short* objs = objects + (size_t)i * 13;
  global const uchar* base = atlas + bases[subject[i] * 3 + view] + (size_t)y * W;
  global uchar* row = out + ((size_t)i * H + y) * W;

  Layers L;
  composite_layers(&L, objs, sprites, places, sensor, r_begin, r_end, y, placement, jx, jy, seed, index);

  Tiles T;
  T.count = 0;
  float gain = 0.0f;
  if (sensor == 0 && (flags & FLAG_PATTERN_NOISE)) {
    const uint k = below(draw(seed, index, STREAM_NOISE_PATTERN, 0u).x, (uint)patterns);
    gain = noise_gains[k];
    noise_tiles(&T, objs, sprites, places, noise_offsets[k], tile_size, r_begin, r_end, y);
  }

  // Only the span that layers and tiles cover needs per-pixel work (all of it under
  // pixel noise); the rest of the row is the base, copied 16 bytes at a time.
  int x0 = W, x1 = 0;
  for (int k = 0; k < L.count; ++k) {
    x0 = min(x0, L.x0[k]);
    x1 = max(x1, L.x0[k] + L.width[k]);
  }
  for (int k = 0; k < T.count; ++k) {
    x0 = min(x0, T.x0[k]);
    x1 = max(x1, T.x0[k] + tile_size);
  }
  if (flags & FLAG_PIXEL_NOISE) {
    x0 = 0;
    x1 = W;
  }
  x0 = clamp(x0, 0, W);
  x1 = clamp(x1, x0, W);
  int x = 0;
  for (; x + 16 <= x0; x += 16) vstore16(vload16(0, base + x), 0, row + x);
  for (; x < x0; ++x) row[x] = base[x];
  if (flags & FLAG_PIXEL_NOISE) {
    // The whole row, a Box-Muller pair (one Philox draw) per two pixels, no branch per
    // pixel. Pairs follow the pixel index y*W + x, so an odd W starts rows mid-pair.
    const int p0 = y * W;
    for (; x < W; ++x) {
      const int p = p0 + x;
      const greal2 g = gauss_pair(seed, index, view, p >> 1);
      real v = composite_pixel(&L, atlas, from_pixel(base[x]), x, alpha);
      v = pattern_noise(&T, atlas, tile_size, gain, v, x);
      row[x] = to_pixel(add_gauss(v, sigma, (p & 1) ? g.y : g.x));
      if ((p & 1) == 0 && x + 1 < W) {
        ++x;
        real v1 = composite_pixel(&L, atlas, from_pixel(base[x]), x, alpha);
        v1 = pattern_noise(&T, atlas, tile_size, gain, v1, x);
        row[x] = to_pixel(add_gauss(v1, sigma, g.y));
      }
    }
    return;
  }
  for (; x < x1; ++x) {
    real v = composite_pixel(&L, atlas, from_pixel(base[x]), x, alpha);
    row[x] = to_pixel(pattern_noise(&T, atlas, tile_size, gain, v, x));
  }
  for (; x + 16 <= W; x += 16) vstore16(vload16(0, base + x), 0, row + x);
  for (; x < W; ++x) row[x] = base[x];
}
