// Stage "composite" (thesis algorithm steps 7-8): object sprites, alpha-blended over the
// subject's base image in region order. The host's place table gives each (view,
// variant, region) its sprite's top-left corner; these helpers work one image row at a
// time.

// The arguments of every camera-view stage kernel (stage_<name>) and of the fused
// render_view, in one order, so the host sets them in one place.
//   sprites: int4 (atlas offset, width, height, 0) per (sprite set, variant)
//   places:  int2 (x0, y0) per (view, variant, region), the sprite centred in its region
//   field:   the view's values before display, n * height * width, at the build's precision
#define VIEW_STAGE_ARGS                                                                                          \
  global const uchar *atlas, global const int *bases, global const int4 *sprites, global const int2 *places,     \
      global const int *noise_offsets, global const float *noise_gains, global const uchar *subject,             \
      global const short *objects, PsViewLaunch L, param alpha, param sigma, global real *field, global uchar *out

// The scenario and image row of a work-item (one per (scenario, row)).
#define VIEW_STAGE_ROW                                           \
  const size_t gid = get_global_id(0);                           \
  const uint i = (uint)(gid / (size_t)L.height);                 \
  const int y = (int)(gid % (size_t)L.height);                   \
  if (i >= L.n) return;                                          \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);              \
  const ulong index = upsample(L.first_hi, L.first_lo) + i;      \
  global const short* objs = objects + (size_t)i * PS_REGIONS;   \
  const size_t row0 = ((size_t)i * L.height + y) * L.width;      \
  (void)seed;                                                    \
  (void)index;                                                   \
  (void)objs

typedef struct {
  int count;
  int bilinear;
  int offset[PS_MAX_LAYERS];  // atlas offset of the sprite's row that meets this image row
  int x0[PS_MAX_LAYERS];
  int width[PS_MAX_LAYERS];
  // Bilinear placement: the second sprite row (-1 if outside), its weight, and the
  // sub-pixel x origin. offset[k] is -1 when only the second row is inside.
  int offset1[PS_MAX_LAYERS];
  float wy[PS_MAX_LAYERS];
  float fx[PS_MAX_LAYERS];
} Layers;

inline int4 sprite_of(global const int4* sprites, const PsViewLaunch* L, int v) {
  return sprites[L->sprite_set * L->variants + v];
}
inline int2 place_of(global const int2* places, const PsViewLaunch* L, int v, int r) {
  return places[((size_t)L->view * L->variants + v) * PS_REGIONS + r];
}

// Collects the sprites of the view's regions that cross row y. With jitter, each
// region's sprite moves by (jx, jy) * (2u - 1), u uniform from the counter generator:
// rounded to whole pixels (integer placement) or kept (bilinear placement).
inline void composite_layers(Layers* Ly, global const short* objects, global const int4* sprites,
                             global const int2* places, const PsViewLaunch* L, int y, uint2 seed, ulong index) {
  Ly->count = 0;
  Ly->bilinear = (L->flags & PS_FLAG_BILINEAR) != 0;
  for (int r = 0; r < PS_REGIONS; ++r) {
    const int v = objects[r];
    if (v < 0 || !((L->region_mask >> r) & 1u)) continue;
    const int4 sp = sprite_of(sprites, L, v);
    const int2 pl = place_of(places, L, v, r);
    float dx = 0.0f, dy = 0.0f;
    if (L->jitter_x > 0.0f || L->jitter_y > 0.0f) {
      const uint4 q = draw(seed, index, PS_STREAM_JITTER, (uint)r);
      dx = L->jitter_x * (2.0f * uniform24(q.x) - 1.0f);
      dy = L->jitter_y * (2.0f * uniform24(q.y) - 1.0f);
    }
    if (!Ly->bilinear) {
      const int x0 = pl.x + (int)floor(dx + 0.5f);
      const int y0 = pl.y + (int)floor(dy + 0.5f);
      if (y < y0 || y >= y0 + sp.z) continue;
      const int k = Ly->count++;
      Ly->offset[k] = sp.x + (y - y0) * sp.y * 2;
      Ly->x0[k] = x0;
      Ly->width[k] = sp.y;
    } else {
      const float fx = (float)pl.x + dx;
      const float sy = (float)y - ((float)pl.y + dy);
      const float j0f = floor(sy);
      const int j0 = (int)j0f;
      if (j0 < -1 || j0 >= sp.z) continue;
      const int k = Ly->count++;
      Ly->offset[k] = j0 >= 0 ? sp.x + j0 * sp.y * 2 : -1;
      Ly->offset1[k] = j0 + 1 < sp.z ? sp.x + (j0 + 1) * sp.y * 2 : -1;
      Ly->wy[k] = sy - j0f;
      Ly->fx[k] = fx;
      Ly->x0[k] = (int)floor(fx);
      Ly->width[k] = sp.y + 1;  // the span a sub-pixel sprite can touch
    }
  }
}

// Bilinear sample of a sprite layer at pixel x: premultiplied value and coverage, 0..1.
inline void bilinear_sample(const Layers* Ly, int k, global const uchar* atlas, int x, greal* pv, greal* cov) {
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

inline global const uchar* base_row(global const uchar* atlas, global const int* bases, global const uchar* subject,
                                    const PsViewLaunch* L, uint i, int y) {
  return atlas + bases[subject[i] * L->views + L->view] + (size_t)y * L->width;
}

kernel void stage_composite(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  Layers Ly;
  composite_layers(&Ly, objs, sprites, places, &L, y, seed, index);
  for (int x = 0; x < L.width; ++x) field[row0 + x] = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
}
