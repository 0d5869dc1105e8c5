// Declared fast path: the thesis chain of one camera view (composite -> pattern_noise ->
// sensor_noise -> display) fused into one kernel, one work-item per (scenario, image
// row). Tested bit for bit against the chain of stage kernels and within the tiers'
// tolerances against the chain of reference stages.

#if defined(VECTOR_RENDER)
// Pixels x .. x + 15 of a row: base, layers, pattern noise and (noisy) the draws g.
__attribute__((always_inline)) inline void render_chunk16(global const uchar* atlas, global const uchar* base, global uchar* row, int x,
                           const Layers* Ly, const Tiles* T, int tile_size, float gain, param alpha, param sigma,
                           int noisy, float16 g) {
  const uchar16 b = load16(base + x);
  int touched = noisy;
  for (int k = 0; k < Ly->count; ++k) touched |= x - Ly->x0[k] > -16 && x - Ly->x0[k] < Ly->width[k];
  for (int k = 0; k < T->count; ++k) touched |= x - T->x0[k] > -16 && x - T->x0[k] < tile_size;
  if (!touched) {
    store16(b, row + x);
    return;
  }
  real16 v = from_pixel16(b);
  for (int k = 0; k < Ly->count; ++k) {
    const int sx = x - Ly->x0[k];
    if (sx <= -16 || sx >= Ly->width[k]) continue;
    global const uchar* vr = atlas + Ly->voff[k] + PS_PAD + sx;
    v = blend16(v, load16(vr), load16(vr + Ly->width[k] + 2 * PS_PAD), alpha);
  }
  if (T->count > 0) {
    real16 nsum = real16_zero();
    for (int k = 0; k < T->count; ++k) {
      const int tx = x - T->x0[k];
      if (tx <= -16 || tx >= tile_size) continue;
      nsum = noise_acc16(nsum, load16(atlas + T->poff[k] + PS_PAD + tx));
    }
    v = add_noise16(v, gain, nsum);
  }
  if (noisy) v = add_gauss16(v, sigma, g);
  store16(to_pixel16(v), row + x);
}
#endif

kernel void render_view(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  (void)field;
  const int W = L.width;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  global uchar* row = out + row0;

  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  Tiles T;
  noise_tiles(&T, rec, noise_offsets, &L, y);
  const float gain = pattern_gain(rec, noise_gains);
  const int tile_size = L.tile_size;
  const int noisy = (L.flags & PS_FLAG_PIXEL_NOISE) != 0;

#if defined(VECTOR_RENDER)
  // 16 pixels at a time, every step element for element as the pixel path below: sprites
  // and tiles read from their padded copies (out-of-sprite pixels have coverage 0, which
  // blends to the same value; tile padding is 128, which adds 0). The last chunk overlaps
  // the one before it when the step does not divide W. Under pixel noise the step is 32
  // pixels (16 Box-Muller pairs), and rows must start on a pair (W even).
  if (!Ly.bilinear && !noisy && W >= 16) {
    for (int xc = 0; xc < W; xc += 16)
      render_chunk16(atlas, base, row, min(xc, W - 16), &Ly, &T, tile_size, gain, alpha, sigma, 0, (float16)(0.0f));
    return;
  }
  if (!Ly.bilinear && noisy && W >= 32 && (W & 1) == 0) {
    for (int xc = 0; xc < W; xc += 32) {
      const int x = min(xc, W - 32);
      float16 g0, g1;
      gauss32(seed, index, PS_STREAM_PIXEL_NOISE, L.view, (y * W + x) >> 1, &g0, &g1);
      render_chunk16(atlas, base, row, x, &Ly, &T, tile_size, gain, alpha, sigma, 1, g0);
      render_chunk16(atlas, base, row, x + 16, &Ly, &T, tile_size, gain, alpha, sigma, 1, g1);
    }
    return;
  }
#endif

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
  for (; x + 16 <= x0; x += 16) store16(load16(base + x), row + x);
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
  for (; x + 16 <= W; x += 16) store16(load16(base + x), row + x);
  for (; x < W; ++x) row[x] = base[x];
}
