// Helpers (kernels/lib/): a row's object layers from the scenario's placement record (the
// composite stage's, read by every stage that lays objects: radiometry, contact_shadow and
// the fast paths), their sampling and blend (composite_pixel), and the noise pattern's
// tiles (pattern_noise).

typedef struct {
  int count;
  int bilinear;
  int offset[PS_MAX_LAYERS];  // atlas offset of the sprite's row that meets this image row
  int voff[PS_MAX_LAYERS];    // the same row of the padded copy (integer placement)
  int x0[PS_MAX_LAYERS];
  int width[PS_MAX_LAYERS];
  int variant[PS_MAX_LAYERS];
  // Bilinear placement: the second sprite row (-1 if outside), its weight, and the
  // sub-pixel x origin. offset[k] is -1 when only the second row is inside.
  int offset1[PS_MAX_LAYERS];
  float wy[PS_MAX_LAYERS];
  float fx[PS_MAX_LAYERS];
  // Affine placement (bilinear is set too; x0 and width are the layer's box on this row,
  // offset[k] the sprite's first row): the sprite's size, the centre's column, and the
  // sprite point of pixel x, (rx + ax (x - cx), ry + ay (x - cx)).
  int affine;
  int sw[PS_MAX_LAYERS], sh[PS_MAX_LAYERS];
  greal cx[PS_MAX_LAYERS], rx[PS_MAX_LAYERS], ry[PS_MAX_LAYERS], ax[PS_MAX_LAYERS], ay[PS_MAX_LAYERS];
} Layers;

// A value of the affine record (kernels/contract.h, PS_LAYER_CX..A11) at greal precision,
// two ints wide.
inline void put_greal(global int* p, greal v) {
#if defined(PRECISION_FP64)
  vstore2(as_int2(v), 0, p);
#else
  p[0] = as_int(v);
  p[1] = 0;
#endif
}
inline greal get_greal(global const int* p) {
#if defined(PRECISION_FP64)
  return as_double(vload2(0, p));
#else
  return as_float(p[0]);
#endif
}

// The image rows a layer of the record can touch (with the bilinear fringe): first in x,
// one past the last in y.
inline int2 layer_rows(global const int* ly, int flags) {
  if (flags & PS_FLAG_AFFINE) return (int2)(ly[PS_LAYER_BY0], ly[PS_LAYER_BY1] + 1);
  const int top = (flags & PS_FLAG_BILINEAR) ? (int)floor(as_float(ly[PS_LAYER_FY])) - 1 : ly[PS_LAYER_Y0];
  return (int2)(top, top + ly[PS_LAYER_H] + 2);
}

// Collects the affine layers of the scenario's record whose box crosses row y, with
// their inverse map along the row.
inline void affine_layers(Layers* Ly, global const int* rec, int y) {
  for (int j = 0; j < rec[PS_REC_COUNT]; ++j) {
    global const int* ly = rec + PS_REC_LAYERS + j * PS_LAYER_LEN;
    if (y < ly[PS_LAYER_BY0] || y > ly[PS_LAYER_BY1]) continue;
    const int k = Ly->count++;
    const int w = ly[PS_LAYER_W], h = ly[PS_LAYER_H];
    Ly->variant[k] = ly[PS_LAYER_VARIANT];
    Ly->offset[k] = ly[PS_LAYER_OFFSET];
    Ly->sw[k] = w;
    Ly->sh[k] = h;
    Ly->x0[k] = ly[PS_LAYER_BX0];
    Ly->width[k] = ly[PS_LAYER_BX1] - ly[PS_LAYER_BX0] + 1;
    const greal v = (greal)y - get_greal(ly + PS_LAYER_CY);
    Ly->cx[k] = get_greal(ly + PS_LAYER_CX);
    Ly->rx[k] = (greal)(w - 1) * (greal)0.5 + get_greal(ly + PS_LAYER_A01) * v;
    Ly->ry[k] = (greal)(h - 1) * (greal)0.5 + get_greal(ly + PS_LAYER_A11) * v;
    Ly->ax[k] = get_greal(ly + PS_LAYER_A00);
    Ly->ay[k] = get_greal(ly + PS_LAYER_A10);
  }
}

// Collects the layers of the scenario's record that cross row y.
inline void composite_layers(Layers* Ly, global const int* rec, const PsViewLaunch* L, int y) {
  Ly->count = 0;
  Ly->affine = (L->flags & PS_FLAG_AFFINE) != 0;
  Ly->bilinear = (L->flags & PS_FLAG_BILINEAR) != 0 || Ly->affine;  // both sample per pixel
  if (Ly->affine) {
    affine_layers(Ly, rec, y);
    return;
  }
  for (int j = 0; j < rec[PS_REC_COUNT]; ++j) {
    global const int* ly = rec + PS_REC_LAYERS + j * PS_LAYER_LEN;
    const int w = ly[PS_LAYER_W], h = ly[PS_LAYER_H];
    Ly->variant[Ly->count] = ly[PS_LAYER_VARIANT];
    if (!Ly->bilinear) {
      const int y0 = ly[PS_LAYER_Y0];
      if (y < y0 || y >= y0 + h) continue;
      const int k = Ly->count++;
      Ly->offset[k] = ly[PS_LAYER_OFFSET] + (y - y0) * w * 2;
      Ly->voff[k] = ly[PS_LAYER_PADDED] + (y - y0) * 2 * (w + 2 * PS_PAD);
      Ly->x0[k] = ly[PS_LAYER_X0];
      Ly->width[k] = w;
    } else {
      const float fx = as_float(ly[PS_LAYER_FX]);
      const float sy = (float)y - as_float(ly[PS_LAYER_FY]);
      const float j0f = floor(sy);
      const int j0 = (int)j0f;
      if (j0 < -1 || j0 >= h) continue;
      const int k = Ly->count++;
      const int off = ly[PS_LAYER_OFFSET];
      Ly->offset[k] = j0 >= 0 ? off + j0 * w * 2 : -1;
      Ly->offset1[k] = j0 + 1 < h ? off + (j0 + 1) * w * 2 : -1;
      Ly->wy[k] = sy - j0f;
      Ly->fx[k] = fx;
      Ly->x0[k] = (int)floor(fx);
      Ly->width[k] = w + 1;  // the span a sub-pixel sprite can touch
    }
  }
}

// Affine sample of a sprite layer at pixel x: the sprite point the inverse map gives,
// then bilinear on premultiplied coverage as below, over the sprite's four nearest texels.
__attribute__((always_inline)) inline void affine_sample(const Layers* Ly, int k, global const uchar* atlas, int x,
                                                         greal* pv, greal* cov) {
  const greal u = (greal)x - Ly->cx[k];
  const greal sx = Ly->rx[k] + Ly->ax[k] * u, sy = Ly->ry[k] + Ly->ay[k] * u;
  const int w = Ly->sw[k], h = Ly->sh[k];
  *pv = 0;
  *cov = 0;
  // Most of a turned sprite's box maps outside it (no texel has weight): done.
  if (!(sx > (greal)-1 && sy > (greal)-1 && sx < (greal)w && sy < (greal)h)) return;
  const greal i0f = floor(sx), j0f = floor(sy);
  const int i0 = (int)i0f, j0 = (int)j0f;
  const greal tx = sx - i0f, ty = sy - j0f;
  greal p = 0, c = 0;  // sums in registers: stores through pv and cov each texel cost most of the time
  for (int j = 0; j < 2; ++j) {
    const int jj = j0 + j;
    if (jj < 0 || jj >= h) continue;
    const int off = Ly->offset[k] + jj * w * 2;
    const greal wj = j ? ty : (greal)1 - ty;
    for (int i = 0; i < 2; ++i) {
      const int ix = i0 + i;
      if (ix < 0 || ix >= w) continue;
      const greal wgt = wj * (i ? tx : (greal)1 - tx);
#if defined(PRECISION_FP64)
      const greal t = (greal)atlas[off + 2 * ix + 1] / (greal)255;
#else
      const greal t = (greal)atlas[off + 2 * ix + 1] * ((greal)1 / (greal)255);
#endif
      p += wgt * t * (greal)atlas[off + 2 * ix];
      c += wgt * t;
    }
  }
  *pv = p;
  *cov = c;
}

// Bilinear sample of a sprite layer at pixel x: premultiplied value and coverage, 0..1.
inline void bilinear_sample(const Layers* Ly, int k, global const uchar* atlas, int x, greal* pv, greal* cov) {
  if (Ly->affine) {
    affine_sample(Ly, k, atlas, x, pv, cov);
    return;
  }
  const greal sx = (greal)x - (greal)Ly->fx[k];
  const greal i0f = floor(sx);
  const int i0 = (int)i0f;
  const greal tx = sx - i0f, ty = (greal)Ly->wy[k];
  const int w = Ly->width[k] - 1;
  *pv = 0;
  *cov = 0;
  for (int j = 0; j < 2; ++j) {
    const int off = j ? Ly->offset1[k] : Ly->offset[k];
    if (off < 0) continue;
    const greal wj = j ? ty : (greal)1 - ty;
    for (int i = 0; i < 2; ++i) {
      const int ix = i0 + i;
      if (ix < 0 || ix >= w) continue;
      const greal wgt = wj * (i ? tx : (greal)1 - tx);
      const greal c = (greal)atlas[off + 2 * ix + 1] * ((greal)1 / (greal)255);
      *pv += wgt * c * (greal)atlas[off + 2 * ix];
      *cov += wgt * c;
    }
  }
}

// The composited value of pixel x over `base`: each layer in region order.
inline real composite_pixel(const Layers* Ly, global const uchar* atlas, real base, int x, param alpha) {
  real v = base;
  for (int k = 0; k < Ly->count; ++k) {
    const int sx = x - Ly->x0[k];
    if (sx < 0 || sx >= Ly->width[k]) continue;
    if (Ly->bilinear) {
      greal pv, cov;
      bilinear_sample(Ly, k, atlas, x, &pv, &cov);
      v = blend_frac(v, pv, cov, alpha);
      continue;
    }
    const int o = Ly->offset[k] + 2 * sx;
    v = blend(v, atlas[o], atlas[o + 1], alpha);
  }
  return v;
}

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
