// Stage "composite" (thesis algorithm steps 7-8): object sprites, alpha-blended over the
// subject's base image in region order. The host's place table gives each (view,
// variant, region) its sprite's top-left corner; these helpers work one image row at a
// time.

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
  // The reference's formulas, to its last bits where it can: the device's cos and sin.
  const greal rad = deg * (M_PI / 180.0);
  const greal c = cos(rad), sn = sin(rad);
#else
  greal c, sn;  // a polynomial (lib/gauss.cl), so that no device's math library sets the bytes
  sincos_turns(deg * (1.0f / 360.0f), &sn, &c);
#endif
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
  (void)atlas, (void)bases, (void)alpha, (void)field, (void)out, (void)phys, (void)raw, (void)scratch;
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

kernel void stage_composite(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  for (int x = 0; x < L.width; ++x) field[row0 + x] = composite_pixel(&Ly, atlas, from_pixel(base[x]), x, alpha);
}
