// Compositing (thesis algorithm steps 7-8): object sprites, alpha-blended over the
// subject's base image in region order. The host's plan gives each (variant, region)
// its sprite's top-left corner; these helpers work one image row at a time.

#define MAX_LAYERS 13

#define STREAM_JITTER 5u
#define PLACE_INTEGER 0
#define PLACE_BILINEAR 1

// Sprites: int4 (atlas offset, width, height, 0) per variant and sensor (0 MMW, 1 IR).
// Places: int4 (MMW x0, MMW y0, IR x0, IR y0) per variant and region.
typedef struct {
  int count;
  int bilinear;
  int offset[MAX_LAYERS];  // atlas offset of the sprite's row that meets this image row
  int x0[MAX_LAYERS];
  int width[MAX_LAYERS];
  // Bilinear placement: the second sprite row (-1 if outside), its weight, and the
  // sub-pixel x origin. offset[k] is -1 when only the second row is inside.
  int offset1[MAX_LAYERS];
  float wy[MAX_LAYERS];
  float fx[MAX_LAYERS];
} Layers;

// Collects the sprites of regions [r_begin, r_end) that cross row y. With jitter, each
// region's sprite moves by (jx, jy) * (2u - 1), u uniform from the counter generator:
// rounded to whole pixels (integer placement) or kept (bilinear placement).
inline void composite_layers(Layers* L, global const short* objects, global const int4* sprites,
                             global const int4* places, int sensor, int r_begin, int r_end, int y, int placement,
                             float jx, float jy, uint2 seed, ulong index) {
  L->count = 0;
  L->bilinear = placement == PLACE_BILINEAR;
  for (int r = r_begin; r < r_end; ++r) {
    const int v = objects[r];
    if (v < 0) continue;
    const int4 sp = sprites[v * 2 + sensor];
    const int4 pl = places[v * 13 + r];
    float dx = 0.0f, dy = 0.0f;
    if (jx > 0.0f || jy > 0.0f) {
      const uint4 q = draw(seed, index, STREAM_JITTER, (uint)r);
      dx = jx * (2.0f * uniform24(q.x) - 1.0f);
      dy = jy * (2.0f * uniform24(q.y) - 1.0f);
    }
    if (!L->bilinear) {
      const int x0 = (sensor ? pl.z : pl.x) + (int)floor(dx + 0.5f);
      const int y0 = (sensor ? pl.w : pl.y) + (int)floor(dy + 0.5f);
      if (y < y0 || y >= y0 + sp.z) continue;
      const int k = L->count++;
      L->offset[k] = sp.x + (y - y0) * sp.y * 2;
      L->x0[k] = x0;
      L->width[k] = sp.y;
    } else {
      const float fx = (float)(sensor ? pl.z : pl.x) + dx;
      const float sy = (float)y - ((float)(sensor ? pl.w : pl.y) + dy);
      const float j0f = floor(sy);
      const int j0 = (int)j0f;
      if (j0 < -1 || j0 >= sp.z) continue;
      const int k = L->count++;
      L->offset[k] = j0 >= 0 ? sp.x + j0 * sp.y * 2 : -1;
      L->offset1[k] = j0 + 1 < sp.z ? sp.x + (j0 + 1) * sp.y * 2 : -1;
      L->wy[k] = sy - j0f;
      L->fx[k] = fx;
      L->x0[k] = (int)floor(fx);
      L->width[k] = sp.y + 1;  // the span a sub-pixel sprite can touch
    }
  }
}

// Bilinear sample of a sprite layer at pixel x: premultiplied value and coverage, 0..1.
inline void bilinear_sample(const Layers* L, int k, global const uchar* atlas, int x, greal* pv, greal* cov) {
  const greal sx = (greal)x - (greal)L->fx[k];
  const greal i0f = floor(sx);
  const int i0 = (int)i0f;
  const greal tx = sx - i0f, ty = (greal)L->wy[k];
  const int w = L->width[k] - 1;
  *pv = 0;
  *cov = 0;
  for (int j = 0; j < 2; ++j) {
    const int off = j ? L->offset1[k] : L->offset[k];
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
inline real composite_pixel(const Layers* L, global const uchar* atlas, real base, int x, param alpha) {
  real v = base;
  for (int k = 0; k < L->count; ++k) {
    const int sx = x - L->x0[k];
    if (sx < 0 || sx >= L->width[k]) continue;
    if (L->bilinear) {
      greal pv, cov;
      bilinear_sample(L, k, atlas, x, &pv, &cov);
      v = blend_frac(v, pv, cov, alpha);
      continue;
    }
    const int o = L->offset[k] + 2 * sx;
    v = blend(v, atlas[o], atlas[o + 1], alpha);
  }
  return v;
}
