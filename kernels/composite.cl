// Stage "composite" (thesis algorithm steps 7-8): object sprites, alpha-blended over the
// subject's base image in region order. The host's place table gives each (view,
// variant, region) its sprite's top-left corner; these helpers work one image row at a
// time.

// The arguments of every camera-view stage kernel (stage_<name>) and of the fused
// render_view, in one order, so the host sets them in one place.
//   sprites: int4 (atlas offset, width, height, padded offset) per (sprite set, variant)
//   noise_offsets: atlas offset of each noise pattern, then of its padded copy
//   places:  int2 (x0, y0) per (view, variant, region), the sprite centred in its region;
//            then int2 (0, dy) per (subject, view, region), its place's move with the
//            subject's height (Sensor::subject_dy)
//   records: the view's placement record per scenario (kernels/contract.h, PS_REC_*)
//   field:   the view's values before display, n * height * width, at the build's precision
//   phys:    the physics model's parameters (kernels/shared.h, PS_PHYS_*)
//   raw:     physics: the MMW raw grid, n * raw_height * raw_width
//   scratch: physics: a second field, for stages that cannot work in place
//   indices: each scenario's global index where the batch is not contiguous, else null
//            (scenario_index)
#define VIEW_STAGE_ARGS                                                                                          \
  global const uchar *atlas, global const int *bases, global const int4 *sprites, global const int2 *places,     \
      global const int *noise_offsets, global const float *noise_gains, global const uchar *subject,             \
      global const short *objects, PsViewLaunch L, param alpha, param sigma, param sigma_hi, global int *records,                 \
      global real *field, global uchar *out, global const param *phys, global real *raw, global real *scratch,   \
      global const ulong *indices

// The scenario and image row of a work-item (one per (scenario, row)).
#define VIEW_STAGE_ROW                                           \
  const size_t gid = get_global_id(0);                           \
  const uint i = (uint)(gid / (size_t)L.height);                 \
  const int y = (int)(gid % (size_t)L.height);                   \
  if (i >= L.n) return;                                          \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);              \
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);      \
  global const int* rec = records + (size_t)i * PS_REC_LEN;      \
  const size_t row0 = ((size_t)i * L.height + y) * L.width;      \
  (void)seed;                                                    \
  (void)index

// The scenario of a work-item (stages that take a whole view per work-item).
#define VIEW_STAGE_SCENARIO                                  \
  const uint i = (uint)get_global_id(0);                     \
  if (i >= L.n) return;                                      \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);          \
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);  \
  (void)seed;                                                \
  (void)index

// The scenario and raw-grid row of a work-item (physics stages on the MMW raw grid, one
// per (scenario, raw row)); r points at that raw row.
#define RAW_STAGE_ROW                                                                   \
  const size_t gid = get_global_id(0);                                                  \
  const uint i = (uint)(gid / (size_t)L.raw_height);                                    \
  const int j = (int)(gid % (size_t)L.raw_height);                                      \
  if (i >= L.n) return;                                                                 \
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);                                     \
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);                             \
  global preal* r = (global preal*)raw + ((size_t)i * L.raw_height + j) * L.raw_width;  \
  (void)seed;                                                                           \
  (void)index

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

// Randomised objects: region r's draw (host: object_transform, the same numbers) as the
// inverse affine map of its sprite about the sprite's centre (cx, cy), and the box of
// pixels the turned, scaled and mirrored sprite (with its bilinear fringe) can touch.
inline void place_affine(global int* ly, const PsViewLaunch* L, uint2 seed, ulong index, int r, greal cx, greal cy,
                         int w, int h) {
  const uint4 q = draw(seed, index, PS_STREAM_TRANSFORM, (uint)r);
#if defined(PRECISION_FP64)
  greal range[4];
  for (int k = 0; k < 4; ++k) range[k] = as_double((uint2)(L->ranges_fp64[2 * k], L->ranges_fp64[2 * k + 1]));
#else
  const greal range[4] = {L->rotate_lo, L->rotate_hi, L->scale_lo, L->scale_hi};
#endif
  const greal deg = range[0] + (range[1] - range[0]) * (greal)uniform24(q.x);
  const greal s = range[2] + (range[3] - range[2]) * (greal)uniform24(q.y);
  const greal f = (L->flags & PS_FLAG_FLIP) && (q.z >> 31) ? (greal)-1 : (greal)1;
#if defined(PRECISION_FP64)
  const greal rad = deg * (M_PI / 180.0);  // the reference's formulas, to its last bits where it can
#else
  const greal rad = deg * (M_PI_F / 180.0f);
#endif
  const greal c = cos(rad), sn = sin(rad);
  // Forward: image = centre + s R F (sprite - sprite centre), R = [c sn; -sn c] (counter-
  // clockwise with y down), F = diag(f, 1); inverse: sprite = sprite centre + F R^T (image - centre) / s.
  put_greal(ly + PS_LAYER_CX, cx);
  put_greal(ly + PS_LAYER_CY, cy);
  put_greal(ly + PS_LAYER_A00, f * c / s);
  put_greal(ly + PS_LAYER_A01, -f * sn / s);
  put_greal(ly + PS_LAYER_A10, sn / s);
  put_greal(ly + PS_LAYER_A11, c / s);
  const greal hw = (greal)(w + 1) * (greal)0.5, hh = (greal)(h + 1) * (greal)0.5;
  const greal ex = s * (fabs(c) * hw + fabs(sn) * hh), ey = s * (fabs(sn) * hw + fabs(c) * hh);
  ly[PS_LAYER_BX0] = (int)floor(cx - ex);
  ly[PS_LAYER_BX1] = (int)ceil(cx + ex);
  ly[PS_LAYER_BY0] = (int)floor(cy - ey);
  ly[PS_LAYER_BY1] = (int)ceil(cy + ey);
}

// Step "place" before every chain: one work-item per scenario writes the view's record.
// With jitter, each region's sprite moves by (jx, jy) * (2u - 1), u uniform from the
// counter generator: rounded to whole pixels (integer placement) or kept (bilinear).
// Randomised objects (PS_FLAG_AFFINE) add each sprite's inverse affine map and box.
kernel void place_view(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)atlas, (void)bases, (void)alpha, (void)sigma, (void)field, (void)out, (void)phys, (void)raw, (void)scratch;
  const uint2 seed = (uint2)(L.seed_lo, L.seed_hi);
  const ulong index = scenario_index(indices, L.first_lo, L.first_hi, i);
  global const short* objs = objects + (size_t)i * PS_REGIONS;
  global int* rec = records + (size_t)i * PS_REC_LEN;
  rec[PS_REC_PATTERN] = (L.flags & PS_FLAG_PATTERN_NOISE)
                            ? (int)below(draw(seed, index, PS_STREAM_NOISE_PATTERN, 0u).x, (uint)L.patterns)
                            : -1;
  int count = 0;
  for (int r = 0; r < PS_REGIONS; ++r) {
    const int v = objs[r];
    if (v < 0 || !((L.region_mask >> r) & 1u)) continue;
    const int4 sp = sprites[L.sprite_set * L.variants + v];
    // The region's place for this view and variant, moved with the subject's height.
    const int2 pl = places[((size_t)L.view * L.variants + v) * PS_REGIONS + r] +
                    places[((size_t)L.views * L.variants + (size_t)subject[i] * L.views + L.view) * PS_REGIONS + r];
    float dx = 0.0f, dy = 0.0f;
    if (L.jitter_x > 0.0f || L.jitter_y > 0.0f) {
      const uint4 q = draw(seed, index, PS_STREAM_JITTER, (uint)r);
      dx = L.jitter_x * (2.0f * uniform24(q.x) - 1.0f);
      dy = L.jitter_y * (2.0f * uniform24(q.y) - 1.0f);
    }
    global int* ly = rec + PS_REC_LAYERS + count * PS_LAYER_LEN;
    ly[PS_LAYER_X0] = pl.x + (int)floor(dx + 0.5f);
    ly[PS_LAYER_Y0] = pl.y + (int)floor(dy + 0.5f);
    ly[PS_LAYER_FX] = as_int((float)pl.x + dx);
    ly[PS_LAYER_FY] = as_int((float)pl.y + dy);
    ly[PS_LAYER_W] = sp.y;
    ly[PS_LAYER_H] = sp.z;
    ly[PS_LAYER_OFFSET] = sp.x;
    ly[PS_LAYER_PADDED] = sp.w;
    ly[PS_LAYER_TILE_X0] = pl.x + (sp.y >> 1) - (L.tile_size >> 1);
    ly[PS_LAYER_TILE_Y0] = pl.y + (sp.z >> 1) - (L.tile_size >> 1);
    ly[PS_LAYER_VARIANT] = v;
    if (L.flags & PS_FLAG_AFFINE) {
      const greal ox = (L.flags & PS_FLAG_BILINEAR) ? (greal)dx : (greal)floor(dx + 0.5f);
      const greal oy = (L.flags & PS_FLAG_BILINEAR) ? (greal)dy : (greal)floor(dy + 0.5f);
      place_affine(ly, &L, seed, index, r, (greal)pl.x + ox + (greal)(sp.y - 1) * (greal)0.5,
                   (greal)pl.y + oy + (greal)(sp.z - 1) * (greal)0.5, sp.y, sp.z);
    }
    ++count;
  }
  rec[PS_REC_COUNT] = count;
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

inline global const uchar* base_row(global const uchar* atlas, global const int* bases, global const uchar* subject,
                                    const PsViewLaunch* L, uint i, int y) {
  return atlas + bases[subject[i] * L->views + L->view] + (size_t)y * L->width;
}
// The same row of the base's fold pattern (host: AssetSet::folds), after every subject's bases.
inline global const uchar* fold_row(global const uchar* atlas, global const int* bases, global const uchar* subject,
                                    const PsViewLaunch* L, uint i, int y) {
  return atlas + bases[(L->subjects + subject[i]) * L->views + L->view] + (size_t)y * L->width;
}

kernel void stage_composite(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  for (int x = 0; x < L.width; ++x) field[row0 + x] = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
}
