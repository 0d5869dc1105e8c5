// Declared fast path: the thesis chain of one camera view (composite -> pattern_noise ->
// sensor_noise -> display) fused into one kernel, one work-item per scenario drawing the
// whole view. Tested bit for bit against the chain of stage kernels and within the tiers'
// tolerances against the chain of reference stages.

// One image row by the stage kernels' per-pixel helpers: the fp64 build, bilinear
// placement, and views too small for the vector path.
inline void render_row(global const uchar* atlas, global const uchar* base, global uchar* row, global const int* rec,
                       global const int* noise_offsets, global const float* noise_gains, const PsViewLaunch* L,
                       param alpha, param sigma, uint2 seed, ulong index, int y) {
  const int W = L->width;
  Layers Ly;
  composite_layers(&Ly, rec, L, y);
  Tiles T;
  noise_tiles(&T, rec, noise_offsets, L, y);
  const float gain = pattern_gain(rec, noise_gains);
  const int tile_size = L->tile_size;
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
  if (L->flags & PS_FLAG_PIXEL_NOISE) {
    x0 = 0;
    x1 = W;
  }
  x0 = clamp(x0, 0, W);
  x1 = clamp(x1, x0, W);
  int x = 0;
  for (; x + 16 <= x0; x += 16) store16(load16(base + x), row + x);
  for (; x < x0; ++x) row[x] = base[x];
#if defined(NOISE_DRAW_IH)
  if (L->flags & PS_FLAG_PIXEL_NOISE) {
    for (; x < W; ++x) {
      real v = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
      v = pattern_noise(&T, atlas, tile_size, gain, v, x);
      row[x] = to_pixel(add_gauss(v, sigma, ih_pixel(seed, index, L->view, y * W + x)));
    }
    return;
  }
#endif
  if (L->flags & PS_FLAG_PIXEL_NOISE) {
    // The whole row, a Box-Muller pair (one Philox draw) per two pixels, no branch per
    // pixel. Pairs follow the pixel index y*W + x, so an odd W starts rows mid-pair.
    const int p0 = y * W;
    for (; x < W; ++x) {
      const int p = p0 + x;
      const greal2 g = gauss_pair(seed, index, L->view, p >> 1);
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

#if defined(VECTOR_RENDER)
// The scenario's layers (integer placement) and noise tiles, read from its record once.
typedef struct {
  int count, tiles;  // layers; tiles: count when the scenario has a pattern, else 0
  int x0[PS_MAX_LAYERS], y0[PS_MAX_LAYERS], w[PS_MAX_LAYERS], h[PS_MAX_LAYERS], padded[PS_MAX_LAYERS];
  int tx0[PS_MAX_LAYERS], ty0[PS_MAX_LAYERS];
  int tile_padded;  // atlas offset of the pattern's padded copy
} ViewLayers;

// The layers and tiles that cross one row, in record (region) order: x origin, width and
// the atlas offset of the row in their padded copies.
typedef struct {
  int n, nt;
  int x0[PS_MAX_LAYERS], w[PS_MAX_LAYERS], off[PS_MAX_LAYERS];
  int tx0[PS_MAX_LAYERS], toff[PS_MAX_LAYERS];
} RowLayers;

inline void view_layers(ViewLayers* V, global const int* rec, global const int* noise_offsets, const PsViewLaunch* L) {
  V->count = rec[PS_REC_COUNT];
  const int pattern = rec[PS_REC_PATTERN];
  V->tiles = pattern < 0 ? 0 : V->count;
  V->tile_padded = pattern < 0 ? 0 : noise_offsets[L->patterns + pattern];
  for (int j = 0; j < V->count; ++j) {
    global const int* ly = rec + PS_REC_LAYERS + j * PS_LAYER_LEN;
    V->x0[j] = ly[PS_LAYER_X0];
    V->y0[j] = ly[PS_LAYER_Y0];
    V->w[j] = ly[PS_LAYER_W];
    V->h[j] = ly[PS_LAYER_H];
    V->padded[j] = ly[PS_LAYER_PADDED];
    V->tx0[j] = ly[PS_LAYER_TILE_X0];
    V->ty0[j] = ly[PS_LAYER_TILE_Y0];
  }
}

inline void row_layers(RowLayers* R, const ViewLayers* V, int tile, int y) {
  R->n = 0;
  R->nt = 0;
  for (int j = 0; j < V->count; ++j) {
    const int dy = y - V->y0[j];
    if (dy < 0 || dy >= V->h[j]) continue;
    const int k = R->n++;
    R->x0[k] = V->x0[j];
    R->w[k] = V->w[j];
    R->off[k] = V->padded[j] + dy * 2 * (V->w[j] + 2 * PS_PAD) + PS_PAD;
  }
  for (int j = 0; j < V->tiles; ++j) {
    const int dy = y - V->ty0[j];
    if (dy < 0 || dy >= tile) continue;
    const int k = R->nt++;
    R->tx0[k] = V->tx0[j];
    R->toff[k] = V->tile_padded + dy * (tile + 2 * PS_PAD) + PS_PAD;
  }
}

// Pixels x .. x + 15 of a row over base pixels b, before sensor noise: the layers, then
// the pattern noise, element for element as the per-pixel helpers. Sprites and tiles are
// read from their padded copies: out-of-sprite pixels have coverage 0, which blends to the
// same value, and tile padding is 128, which adds 0; so any pixel may be computed.
__attribute__((always_inline)) inline real16 composite16(global const uchar* atlas, const RowLayers* R, uchar16 b,
                                                         int x, int tile, float gain, param alpha) {
  real16 v = from_pixel16(b);
  for (int k = 0; k < R->n; ++k) {
    const int sx = x - R->x0[k];
    if (sx <= -16 || sx >= R->w[k]) continue;
    global const uchar* vr = atlas + R->off[k] + sx;
    v = blend16(v, load16(vr), load16(vr + R->w[k] + 2 * PS_PAD), alpha);
  }
  if (R->nt > 0) {
    real16 nsum = real16_zero();
    for (int k = 0; k < R->nt; ++k) {
      const int tx = x - R->tx0[k];
      if (tx <= -16 || tx >= tile) continue;
      nsum = noise_acc16(nsum, load16(atlas + R->toff[k] + tx));
    }
    v = add_noise16(v, gain, nsum);
  }
  return v;
}

// 64 bytes at any address.
typedef uint16 __attribute__((aligned(1))) uint16_any;

// Copies base[p, q) to img[p, q) in 64-byte steps while a whole step fits and returns
// where it stopped. The output (100 KB a scenario) does not fit in cache, so the steps go
// to aligned addresses with non-temporal stores, which skip reading the lines first; one
// plain unaligned step reaches the alignment.
inline int copy_run(global const uchar* base, global uchar* img, int p, int q) {
  if (q - p < 128) return p;
  *(global uint16_any*)(img + p) = *(global const uint16_any*)(base + p);
  p += 64 - (int)((size_t)(img + p) & 63);
  for (; p + 64 <= q; p += 64) {
    const uint16 v = *(global const uint16_any*)(base + p);
    __builtin_nontemporal_store(v, (global uint16*)(img + p));
  }
  return p;
}

// Bytes [p, q) of the base image into the view's image. Writes up to 15 bytes past q: the
// caller draws a span of at least 16 pixels there next.
inline void copy_gap(global const uchar* base, global uchar* img, int p, int q) {
  for (p = copy_run(base, img, p, q); p < q; p += 16) store16(load16(base + p), img + p);
}

// Without pixel noise: the rows no layer or tile crosses are one flat copy of the base
// image; the rest copy around the span the row's layers and tiles cover.
inline void render_plain(global const uchar* atlas, global const uchar* base, global uchar* img, const ViewLayers* V,
                         const PsViewLaunch* L, float gain, param alpha) {
  const int W = L->width, H = L->height, tile = L->tile_size;
  int p = 0;  // the base is copied up to here
  int y = 0;
  while (y < H) {
    // The rows up to the next row where a layer or tile starts or ends all have the
    // same layers and tiles.
    int next = H, any = 0;
    for (int j = 0; j < V->count; ++j) {
      const int a = V->y0[j], e = a + V->h[j];
      if (a > y) next = min(next, a);
      else if (e > y) next = min(next, e), any = 1;
    }
    for (int j = 0; j < V->tiles; ++j) {
      const int a = V->ty0[j], e = a + tile;
      if (a > y) next = min(next, a);
      else if (e > y) next = min(next, e), any = 1;
    }
    if (!any) {
      y = next;
      continue;
    }
    for (; y < next; ++y) {
      RowLayers R;
      row_layers(&R, V, tile, y);
      int s = W, e = 0;
      for (int k = 0; k < R.n; ++k) s = min(s, R.x0[k]), e = max(e, R.x0[k] + R.w[k]);
      for (int k = 0; k < R.nt; ++k) s = min(s, R.tx0[k]), e = max(e, R.tx0[k] + tile);
      s = max(s, 0);
      e = min(e, W);
      if (e <= s) continue;
      if (e - s < 16) {
        e = min(W, s + 16);
        s = e - 16;
      }
      const int r = y * W;
      copy_gap(base, img, p, r + s);
      // 16 pixels at a time; the last chunk overlaps the one before it.
      for (int xc = s; xc < e; xc += 16) {
        const int x = min(xc, e - 16);
        store16(to_pixel16(composite16(atlas, &R, load16(base + r + x), x, tile, gain, alpha)), img + r + x);
      }
      p = r + e;
    }
  }
  const int HW = W * H;
  for (p = copy_run(base, img, p, HW); p + 16 <= HW; p += 16) store16(load16(base + p), img + p);
  for (; p < HW; ++p) img[p] = base[p];
  // Non-temporal stores are weakly ordered: make them visible before the kernel ends.
#if defined(__SSE__)
  __builtin_ia32_sfence();
#else
  mem_fence(CLK_GLOBAL_MEM_FENCE);
#endif
}

// 16 pixels from flat position p (row *y, column *x) with their draws g, then on to the
// next 16. A run that crosses the row end takes each pixel from its own row's layers.
__attribute__((always_inline)) inline void noisy16(global const uchar* atlas, global const uchar* base,
                                                   global uchar* img, const ViewLayers* V, RowLayers* R, int* cur,
                                                   int* y, int* x, int p, int W, int tile, float gain, param alpha,
                                                   param sigma, float16 g) {
  const uchar16 b = load16(base + p);
  real16 v = composite16(atlas, &R[*cur], b, *x, tile, gain, alpha);
  if (*x + 16 > W) {
    const real16 v1 = composite16(atlas, &R[*cur ^ 1], b, *x - W, tile, gain, alpha);
    v = select(v, v1, (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15) >= W - *x);
  }
  store16(to_pixel16(add_gauss16(v, sigma, g)), img + p);
  *x += 16;
  if (*x >= W) {
    *x -= W;
    ++*y;
    *cur ^= 1;
    row_layers(&R[*cur ^ 1], V, tile, *y + 1);
  }
}

// A flat run of pixels starting at pixel p: its (x, y), and rows y and y + 1 in R (R[0] is row y).
inline void run_from(RowLayers* R, const ViewLayers* V, int tile, int W, int p, int* y, int* x, int* cur) {
  *y = p / W;
  *x = p - *y * W;
  *cur = 0;
  row_layers(&R[0], V, tile, *y);
  row_layers(&R[1], V, tile, *y + 1);
}

#if defined(NOISE_DRAW_IH)
// With pixel noise every pixel is drawn, in flat runs of 128 pixels (one set of 16 Philox
// draws), 16 at a time; the last HW % 16 pixels as one run of 16 that overlaps the one
// before it, its draws taken pixel by pixel.
inline void render_noisy(global const uchar* atlas, global const uchar* base, global uchar* img, const ViewLayers* V,
                         const PsViewLaunch* L, float gain, param alpha, param sigma, uint2 seed, ulong index) {
  const int W = L->width, H = L->height, tile = L->tile_size, HW = W * H;
  RowLayers R[2];  // rows y and y + 1, R[cur] is row y
  int y, x, cur;
  run_from(R, V, tile, W, 0, &y, &x, &cur);
  int c = 0;
  while (c + 16 <= HW) {
    float16 g[8];
    ih128(seed, index, PS_STREAM_PIXEL_NOISE_FAST, L->view, c >> 7, g);
    for (int h = 0; h < 8 && c + 16 <= HW; ++h, c += 16)
      noisy16(atlas, base, img, V, R, &cur, &y, &x, c, W, tile, gain, alpha, sigma, g[h]);
  }
  if (c < HW) {
    const int p = HW - 16;
    run_from(R, V, tile, W, p, &y, &x, &cur);
    float t[16];
    for (int k = 0; k < 16; ++k) t[k] = ih_pixel(seed, index, L->view, p + k);
    noisy16(atlas, base, img, V, R, &cur, &y, &x, p, W, tile, gain, alpha, sigma, vload16(0, t));
  }
}
#else
// With pixel noise every pixel is drawn, in flat runs of 64 pixels (32 Box-Muller pairs
// of the pixel index, so HW must be even; two Philox chains that overlap), then of 32; the
// last run overlaps the one before it.
inline void render_noisy(global const uchar* atlas, global const uchar* base, global uchar* img, const ViewLayers* V,
                         const PsViewLaunch* L, float gain, param alpha, param sigma, uint2 seed, ulong index) {
  const int W = L->width, H = L->height, tile = L->tile_size, HW = W * H;
  RowLayers R[2];  // rows y and y + 1, R[cur] is row y
  int y, x, cur;
  run_from(R, V, tile, W, 0, &y, &x, &cur);
  int c = 0;
  for (; c + 64 <= HW; c += 64) {
    float16 g[4];
    gauss64(seed, index, PS_STREAM_PIXEL_NOISE, L->view, c >> 1, g);
    for (int h = 0; h < 4; ++h)
      noisy16(atlas, base, img, V, R, &cur, &y, &x, c + 16 * h, W, tile, gain, alpha, sigma, g[h]);
  }
  for (; c < HW; c += 32) {
    const int p = min(c, HW - 32);
    if (p != c) run_from(R, V, tile, W, p, &y, &x, &cur);
    float16 g[2];
    gauss32(seed, index, PS_STREAM_PIXEL_NOISE, L->view, p >> 1, &g[0], &g[1]);
    for (int h = 0; h < 2; ++h)
      noisy16(atlas, base, img, V, R, &cur, &y, &x, p + 16 * h, W, tile, gain, alpha, sigma, g[h]);
  }
}
#endif
#endif

kernel void render_view(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)sprites, (void)places, (void)objects, (void)field, (void)phys, (void)raw, (void)scratch;
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);
  global const int* rec = records + (size_t)i * PS_REC_LEN;
  const int W = L.width, H = L.height;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, 0);
  global uchar* img = out + (size_t)i * H * W;
  const param sigma = pixel_sigma_of(phys, seed, index);

#if defined(VECTOR_RENDER)
  // The vector paths: integer placement (no sub-pixel or affine sprites), and rows of at
  // least 16 pixels (with Box-Muller pixel noise, rows of at least 32 that start on a pair).
  const int noisy = (L.flags & PS_FLAG_PIXEL_NOISE) != 0;
#if defined(NOISE_DRAW_IH)
  const int vector_ok = W >= 16;  // Irwin-Hall draws are per pixel: no pairs to keep
#else
  const int vector_ok = noisy ? W >= 32 && (W & 1) == 0 : W >= 16;
#endif
  if (!(L.flags & (PS_FLAG_BILINEAR | PS_FLAG_AFFINE)) && vector_ok) {
    ViewLayers V;
    view_layers(&V, rec, noise_offsets, &L);
    const float gain = pattern_gain(rec, noise_gains);
    if (noisy)
      render_noisy(atlas, base, img, &V, &L, gain, alpha, sigma, seed, index);
    else
      render_plain(atlas, base, img, &V, &L, gain, alpha);
    return;
  }
#endif
  for (int y = 0; y < H; ++y)
    render_row(atlas, base + (size_t)y * W, img + (size_t)y * W, rec, noise_offsets, noise_gains, &L, alpha, sigma, seed,
               index, y);
}
