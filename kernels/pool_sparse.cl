// ---------------------------------------------------------------------------------
// Sparse block averaging for features-only runs (no per-pixel noise): blocks that no
// object touches keep the subject's precomputed base means, and an object's effect on
// the blocks and regions it touches comes from a table made once per run
// (footprint_deltas). Only pixels where two objects' footprints overlap are rendered
// per scenario. Every value is the dense path's to the bit: the same blend() and noise
// arithmetic, integer sums, and the same final division.
//
// The footprint record per (variant, region, subject: the place moves with its height)
// is laid out in kernels/contract.h (PS_FP_*).
// Pooled views: `pooled[k]` is the camera view of the k-th pooled view (its blocks are
// the k-th run of the row); `region_slot[r]` is the pooled view region r lies in, and
// rects[r] its rectangle there.
#define FP_LEN PS_FP_LEN

inline int block_count(int bx, int by, int block, int W, int H) {
  return (min(bx * block + block, W) - bx * block) * (min(by * block + block, H) - by * block);
}

// Base means and sums of every subject: one work-item per (subject, feature), features
// as in a row (upper blocks, lower blocks, regions).
kernel void base_features(global const uchar* atlas, global const int* bases, global const int4* rects,
                          global const int* pooled, int npooled, int views, global const int* region_slot, int S,
                          int W, int H, int block, int bx_count, int by_count, int row_len, global int* sums,
                          global float* means) {
  const int g = (int)get_global_id(0);
  if (g >= S * row_len) return;
  const int s = g / row_len, f = g % row_len, per_view = bx_count * by_count;
  uint sum = 0;
  int count;
  if (f < npooled * per_view) {
    const int slot = f / per_view, b = f % per_view;
    const int x0 = (b % bx_count) * block, y0 = (b / bx_count) * block;
    const int x1 = min(x0 + block, W), y1 = min(y0 + block, H);
    global const uchar* img = atlas + bases[s * views + pooled[slot]];
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) sum += img[y * W + x];
    count = (x1 - x0) * (y1 - y0);
  } else {
    const int r = f - npooled * per_view;
    const int4 rc = rects[r];
    global const uchar* img = atlas + bases[s * views + pooled[region_slot[r]]];
    for (int y = rc.y; y < rc.y + rc.w; ++y)
      for (int x = rc.x; x < rc.x + rc.z; ++x) sum += img[y * W + x];
    count = rc.z * rc.w;
  }
  sums[g] = (int)sum;
  means[g] = mean_of(sum, count);
}

// The pixel at (x, y) with one object alone over the base: what the dense kernel gives
// wherever no other object reaches.
inline uchar single_pixel(global const uchar* atlas, global const int* fp, uchar base, int x, int y, int W,
                          param alpha, int tile, int tile_offset, float gain, int use_noise) {
  real v = from_pixel(base);
  const int sx = x - fp[PS_FP_SPRITE_X0], sy = y - fp[PS_FP_SPRITE_Y0];
  if (sx >= 0 && sy >= 0 && sx < fp[PS_FP_SPRITE_W] && sy < fp[PS_FP_SPRITE_H]) {
    const int o = fp[PS_FP_SPRITE_OFFSET] + (sy * fp[PS_FP_SPRITE_W] + sx) * 2;
    v = blend(v, atlas[o], atlas[o + 1], alpha);
  }
  if (use_noise) {
    real n = real_zero();
    const int tx = x - fp[PS_FP_TILE_X0], ty = y - fp[PS_FP_TILE_Y0];
    if (tx >= 0 && ty >= 0 && tx < tile && ty < tile) n = noise_acc(n, atlas[tile_offset + ty * tile + tx]);
    v = add_noise(v, gain, n);
  }
  return to_pixel(v);
}

// One work-item per (variant, region, subject, pattern): the sums of (pixel - base)
// over each block of the footprint and over each region.
kernel void footprint_deltas(global const uchar* atlas, global const int* bases, global const int* fps,
                             global const int* noise_offsets, global const float* noise_gains,
                             global const int4* rects, global const int* pooled, int views,
                             global const int* region_slot, int combos, int S, int P, int W, int block, param alpha,
                             int tile, int use_noise, global int* deltas, global int* region_deltas) {
  const int g = (int)get_global_id(0);
  if (g >= combos) return;
  const int p = g % P, s = (g / P) % S, vr = g / (P * S), r = vr % PS_REGIONS;
  global const int* fp = fps + (vr * S + s) * FP_LEN;  // the place on this subject
  const int slot = region_slot[r];
  global const uchar* base = atlas + bases[s * views + pooled[slot]];
  global int* d = deltas + fp[PS_FP_DELTAS] + p * fp[PS_FP_BLOCKS_W] * fp[PS_FP_BLOCKS_H];
  for (int k = 0; k < fp[PS_FP_BLOCKS_W] * fp[PS_FP_BLOCKS_H]; ++k) d[k] = 0;
  int reg[PS_REGIONS];
  for (int k = 0; k < PS_REGIONS; ++k) reg[k] = 0;
  const int toff = noise_offsets[p];
  const float gain = noise_gains[p];
  for (int y = fp[PS_FP_Y0]; y < fp[PS_FP_Y1]; ++y)
    for (int x = fp[PS_FP_X0]; x < fp[PS_FP_X1]; ++x) {
      const uchar b = base[y * W + x];
      const int diff = (int)single_pixel(atlas, fp, b, x, y, W, alpha, tile, toff, gain, use_noise) - (int)b;
      if (diff == 0) continue;
      d[(y / block - fp[PS_FP_BLOCK_Y0]) * fp[PS_FP_BLOCKS_W] + (x / block - fp[PS_FP_BLOCK_X0])] += diff;
      for (int q = 0; q < PS_REGIONS; ++q) {
        if (region_slot[q] != slot) continue;
        const int4 rc = rects[q];
        if (x >= rc.x && y >= rc.y && x < rc.x + rc.z && y < rc.y + rc.w) reg[q] += diff;
      }
    }
  for (int k = 0; k < PS_REGIONS; ++k) region_deltas[g * PS_REGIONS + k] = reg[k];
}

inline int in_rect(int x, int y, const int* fp) {
  return x >= fp[PS_FP_X0] && y >= fp[PS_FP_Y0] && x < fp[PS_FP_X1] && y < fp[PS_FP_Y1];
}
inline int in_blocks(int bx, int by, const int* fp) {
  return bx >= fp[PS_FP_BLOCK_X0] && by >= fp[PS_FP_BLOCK_Y0] && bx < fp[PS_FP_BLOCK_X0] + fp[PS_FP_BLOCKS_W] && by < fp[PS_FP_BLOCK_Y0] + fp[PS_FP_BLOCKS_H];
}
inline int blocks_meet(const int* a, const int* b) {
  const int ax = a[PS_FP_BLOCK_X0], ay = a[PS_FP_BLOCK_Y0], bx = b[PS_FP_BLOCK_X0], by = b[PS_FP_BLOCK_Y0];
  return max(ax, bx) < min(ax + a[PS_FP_BLOCKS_W], bx + b[PS_FP_BLOCKS_W]) &&
         max(ay, by) < min(ay + a[PS_FP_BLOCKS_H], by + b[PS_FP_BLOCKS_H]);
}

// Each scenario's noise pattern (under pattern noise), apart from features_sparse so that
// PoCL runs the generator across the work-items of a group, in vector registers.
kernel void sparse_patterns(uint n, int P, uint2 seed, uint2 first, global const ulong* indices,
                              global int* patterns) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const ulong index = scenario_index(indices, first.x, first.y, i);
  patterns[i] = (int)below(draw(seed, index, PS_STREAM_NOISE_PATTERN, 0u).x, (uint)P);
}

#if defined(VECTOR_RENDER)
inline int sum16(int16 v) {
  const int8 a = v.lo + v.hi;
  const int4 b = a.lo + a.hi;
  const int2 c = b.lo + b.hi;
  return c.x + c.y;
}
#endif

// One work-item per scenario: a features row from base means, table deltas and the
// overlap pixels rendered here. The scenario's footprint records are copied to private
// memory first, and the pointers are restrict: otherwise every store to the row would
// make the compiler reload them.
kernel void features_sparse(global const uchar* restrict atlas, global const int* restrict bases,
                            global const int* restrict fps, global const int* restrict deltas,
                            global const int* restrict region_deltas, global const int* restrict base_sums,
                            global const float* restrict base_means, global const int* restrict noise_offsets,
                            global const float* restrict noise_gains, global const int4* restrict rects,
                            global const int* restrict pooled, int npooled, int views,
                            global const int* restrict region_slot, global const uchar* restrict subject,
                            global const short* restrict objects, global const int* restrict patterns, uint n,
                            int S, int P, int W, int H, int block, int bx_count, int by_count, param alpha, int tile,
                            int use_noise, int row_len, global float* restrict features) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const int s = subject[i], per_view = bx_count * by_count;
  global const short* objs = objects + (size_t)i * PS_REGIONS;
  global float* row = features + (size_t)i * row_len;
  global const float* bm = base_means + s * row_len;
  global const int* bs = base_sums + s * row_len;
  for (int f = 0; f < row_len; ++f) row[f] = bm[f];
  const int p = use_noise ? patterns[i] : 0;
  const int toff = noise_offsets[p];
  const float gain = noise_gains[p];

  int reg[PS_REGIONS];
  for (int r = 0; r < PS_REGIONS; ++r) reg[r] = bs[npooled * per_view + r];
  int touched_regions = 0;

  for (int slot = 0; slot < npooled; ++slot) {
    int fp[PS_REGIONS][FP_LEN];  // the footprints of this view's objects, in region order
    int comb[PS_REGIONS];
    int cnt = 0;
    for (int r = 0; r < PS_REGIONS; ++r) {
      const int v = objs[r];
      if (v < 0 || region_slot[r] != slot) continue;
      for (int q = 0; q < FP_LEN; ++q) fp[cnt][q] = fps[((v * PS_REGIONS + r) * S + s) * FP_LEN + q];
      comb[cnt] = (v * PS_REGIONS + r) * S * P + s * P + p;
      ++cnt;
    }
    if (cnt == 0) continue;
    touched_regions = 1;
    global float* vrow = row + slot * per_view;
    global const int* vbs = bs + slot * per_view;
    // Touched blocks hold integer sums (exact in float below 2^24) until the division;
    // a block in several footprints is set to its base sum more than once, alike.
    for (int k = 0; k < cnt; ++k)
      for (int by = fp[k][PS_FP_BLOCK_Y0]; by < fp[k][PS_FP_BLOCK_Y0] + fp[k][PS_FP_BLOCKS_H]; ++by)
        for (int bx = fp[k][PS_FP_BLOCK_X0]; bx < fp[k][PS_FP_BLOCK_X0] + fp[k][PS_FP_BLOCKS_W]; ++bx)
          vrow[by * bx_count + bx] = (float)vbs[by * bx_count + bx];
    for (int k = 0; k < cnt; ++k) {
      global const int* d = deltas + fp[k][PS_FP_DELTAS] + p * fp[k][PS_FP_BLOCKS_W] * fp[k][PS_FP_BLOCKS_H];
      for (int by = 0; by < fp[k][PS_FP_BLOCKS_H]; ++by)
        for (int bx = 0; bx < fp[k][PS_FP_BLOCKS_W]; ++bx)
          vrow[(fp[k][PS_FP_BLOCK_Y0] + by) * bx_count + fp[k][PS_FP_BLOCK_X0] + bx] += (float)d[by * fp[k][PS_FP_BLOCKS_W] + bx];
      for (int r = 0; r < PS_REGIONS; ++r) reg[r] += region_deltas[comb[k] * PS_REGIONS + r];
    }
    // Where footprints overlap, the table's single-object values are wrong: replace
    // their sum by the pixel rendered with every object, as the dense kernel does.
    global const uchar* base = atlas + bases[s * views + pooled[slot]];
#if defined(VECTOR_RENDER)
    // 16 pixels of an overlap row at a time, every step element for element as the pixel
    // loop below (so bit for bit): sprites and tiles read from their padded copies, where
    // pixels outside a sprite have coverage 0 (blending to the same value) and outside a
    // tile 128 (adding 0). The last chunk of a row may start left of the rectangle (and
    // overlap the one before it) so as to stay in the view: `mine` masks the lanes this
    // pair corrects.
    if (W >= 16) {
      const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
      const int tpoff = use_noise ? noise_offsets[P + p] : 0;
      for (int a = 0; a < cnt; ++a)
        for (int b = a + 1; b < cnt; ++b) {
          const int x0 = max(fp[a][PS_FP_X0], fp[b][PS_FP_X0]), y0 = max(fp[a][PS_FP_Y0], fp[b][PS_FP_Y0]);
          const int x1 = min(fp[a][PS_FP_X1], fp[b][PS_FP_X1]), y1 = min(fp[a][PS_FP_Y1], fp[b][PS_FP_Y1]);
          for (int y = y0; y < y1; ++y)
            for (int xc = x0; xc < x1; xc += 16) {
              const int xs = min(xc, W - 16);
              const int16 xv = xs + lane;
              const uchar16 bp = load16(base + y * W + xs);
              const int16 bi = convert_int16(bp);
              const real16 b0 = from_pixel16(bp);
              real16 v = b0, nsum = real16_zero();
              int16 singles = (int16)(0), cover = (int16)(0);
              for (int k = 0; k < cnt; ++k) {
                if (y < fp[k][PS_FP_Y0] || y >= fp[k][PS_FP_Y1] || xs + 16 <= fp[k][PS_FP_X0] || xs >= fp[k][PS_FP_X1])
                  continue;
                const int16 in = (xv >= fp[k][PS_FP_X0]) & (xv < fp[k][PS_FP_X1]);
                cover |= in & (int16)(1 << k);
                real16 one = b0;
                const int sx = xs - fp[k][PS_FP_SPRITE_X0], sy = y - fp[k][PS_FP_SPRITE_Y0], sw = fp[k][PS_FP_SPRITE_W];
                if (sy >= 0 && sy < fp[k][PS_FP_SPRITE_H] && sx > -16 && sx < sw) {
                  global const uchar* vr =
                      atlas + fp[k][PS_FP_SPRITE_PADDED] + sy * 2 * (sw + 2 * PS_PAD) + PS_PAD + sx;
                  const uchar16 value = load16(vr), coverage = load16(vr + sw + 2 * PS_PAD);
                  one = blend16(one, value, coverage, alpha);
                  v = blend16(v, value, coverage, alpha);
                }
                if (use_noise) {
                  real16 n1 = real16_zero();
                  const int tx = xs - fp[k][PS_FP_TILE_X0], ty = y - fp[k][PS_FP_TILE_Y0];
                  if (ty >= 0 && ty < tile && tx > -16 && tx < tile) {
                    const uchar16 t = load16(atlas + tpoff + ty * (tile + 2 * PS_PAD) + PS_PAD + tx);
                    n1 = noise_acc16(n1, t);
                    nsum = noise_acc16(nsum, t);
                  }
                  one = add_noise16(one, gain, n1);
                }
                singles += in & (convert_int16(to_pixel16(one)) - bi);
              }
              if (use_noise) v = add_noise16(v, gain, nsum);
              // A pixel in several overlaps is corrected once, with its first two footprints.
              const int16 mine = (xv >= xc) & (xv < x1) & ((cover & (int16)((1 << b) - 1)) == (int16)(1 << a));
              const int16 corr = mine & (convert_int16(to_pixel16(v)) - bi - singles);
              if (!any(corr != 0)) continue;
              int c[16];
              vstore16(corr, 0, c);
              global float* brow = vrow + (y / block) * bx_count;
              for (int j = 0; j < 16; ++j)
                if (c[j] != 0) brow[(xs + j) / block] += (float)c[j];
              for (int r = 0; r < PS_REGIONS; ++r) {
                if (region_slot[r] != slot) continue;
                const int4 rc = rects[r];
                if (y >= rc.y && y < rc.y + rc.w) reg[r] += sum16(corr & (xv >= rc.x) & (xv < rc.x + rc.z));
              }
            }
        }
    } else
#endif
    {
      for (int a = 0; a < cnt; ++a)
        for (int b = a + 1; b < cnt; ++b) {
          const int x0 = max(fp[a][PS_FP_X0], fp[b][PS_FP_X0]), y0 = max(fp[a][PS_FP_Y0], fp[b][PS_FP_Y0]);
          const int x1 = min(fp[a][PS_FP_X1], fp[b][PS_FP_X1]), y1 = min(fp[a][PS_FP_Y1], fp[b][PS_FP_Y1]);
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
              uint cover = 0;  // bit k: footprint k holds the pixel
              for (int k = 0; k < cnt; ++k) cover |= (uint)in_rect(x, y, fp[k]) << k;
              // A pixel in several overlaps is corrected once, with its first two footprints.
              if ((cover & ((1u << b) - 1u)) != (1u << a)) continue;
              const uchar bp = base[y * W + x];
              const real b0 = from_pixel(bp);
              real v = b0, nsum = real_zero();
              int singles = 0;
              for (int k = 0; k < cnt; ++k) {
                if (!(cover & (1u << k))) continue;
                real one = b0, n1 = real_zero();
                const int sx = x - fp[k][PS_FP_SPRITE_X0], sy = y - fp[k][PS_FP_SPRITE_Y0];
                if (sx >= 0 && sy >= 0 && sx < fp[k][PS_FP_SPRITE_W] && sy < fp[k][PS_FP_SPRITE_H]) {
                  const int o = fp[k][PS_FP_SPRITE_OFFSET] + (sy * fp[k][PS_FP_SPRITE_W] + sx) * 2;
                  one = blend(one, atlas[o], atlas[o + 1], alpha);
                  v = blend(v, atlas[o], atlas[o + 1], alpha);
                }
                if (use_noise) {
                  const int tx = x - fp[k][PS_FP_TILE_X0], ty = y - fp[k][PS_FP_TILE_Y0];
                  if (tx >= 0 && ty >= 0 && tx < tile && ty < tile) {
                    const uchar t = atlas[toff + ty * tile + tx];
                    n1 = noise_acc(n1, t);
                    nsum = noise_acc(nsum, t);
                  }
                  one = add_noise(one, gain, n1);
                }
                singles += (int)to_pixel(one) - (int)bp;
              }
              if (use_noise) v = add_noise(v, gain, nsum);
              const int corr = (int)to_pixel(v) - (int)bp - singles;
              if (corr == 0) continue;
              vrow[(y / block) * bx_count + x / block] += (float)corr;
              for (int r = 0; r < PS_REGIONS; ++r) {
                if (region_slot[r] != slot) continue;
                const int4 rc = rects[r];
                if (x >= rc.x && y >= rc.y && x < rc.x + rc.z && y < rc.y + rc.w) reg[r] += corr;
              }
            }
        }
    }
    // Sums to means, each block once: a block of an earlier footprint is done (`near`:
    // the earlier footprints whose blocks meet this one's, mostly none).
    for (int k = 0; k < cnt; ++k) {
      uint near = 0;
      for (int j = 0; j < k; ++j) near |= (uint)blocks_meet(fp[j], fp[k]) << j;
      for (int by = fp[k][PS_FP_BLOCK_Y0]; by < fp[k][PS_FP_BLOCK_Y0] + fp[k][PS_FP_BLOCKS_H]; ++by)
        for (int bx = fp[k][PS_FP_BLOCK_X0]; bx < fp[k][PS_FP_BLOCK_X0] + fp[k][PS_FP_BLOCKS_W]; ++bx) {
          int seen = 0;
          for (uint m = near; m != 0; m &= m - 1) seen |= in_blocks(bx, by, fp[31 - clz(m & -m)]);
          if (!seen) vrow[by * bx_count + bx] = mean_of((uint)vrow[by * bx_count + bx], block_count(bx, by, block, W, H));
        }
    }
  }
  if (touched_regions)
    for (int r = 0; r < PS_REGIONS; ++r) {
      const int4 rc = rects[r];
      row[npooled * per_view + r] = mean_of((uint)reg[r], rc.z * rc.w);
    }
}

// The block-mean noise model (tier "fast", features-only runs with pixel noise): rather
// than drawing sigma * N(0,1) for every pixel, each mean over c pixels gets one draw of
// N(0, sigma^2 / c), clipped to the pixel range. Rounding and clipping of single pixels
// are not modelled; tradeoff measures what that costs. One work-item per scenario.
kernel void analytic_noise(global float* features, global const int4* rects, global const int4* grids, uint n,
                           int block, int npooled, int row_len, global const param* drawn, uint2 seed,
                           uint2 first, global const ulong* indices) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const ulong index = scenario_index(indices, first.x, first.y, i);
  // The scenario's sigma from the run's drawn ranges: the knob's, or its draw, in fp32 in
  // every build (pixel_sigma_of draws at the parameters' precision).
  global const PsDrawn* r = phys_drawn(drawn);
  const float sigma = knob_draw((float)r->lo[PS_DRAWN_PIXEL_NOISE], (float)r->hi[PS_DRAWN_PIXEL_NOISE], seed, index,
                                PS_DRAWN_PIXEL_NOISE);
  // grids: per pooled view (width, height, blocks across, first column); the regions follow.
  const int4 last = grids[npooled - 1];
  const int block_features = last.w + last.z * ((last.y + block - 1) / block);
  global float* row = features + (size_t)i * row_len;
  int slot = 0;
  for (int f = 0; f < row_len; f += 2) {
    const uint4 r = draw(seed, index, PS_STREAM_BLOCK_NOISE, (uint)f);
    float g0, g1;
    box_muller(r.x, r.y, &g0, &g1);  // the per-pixel noise's Box-Muller (lib/gauss.cl)
    for (int k = 0; k < 2 && f + k < row_len; ++k) {
      const int q = f + k;
      int count;
      if (q < block_features) {
        while (slot + 1 < npooled && q >= grids[slot + 1].w) ++slot;
        const int4 v = grids[slot];
        const int b = q - v.w;
        count = block_count(b % v.z, b / v.z, block, v.x, v.y);
      } else {
        const int4 rc = rects[q - block_features];
        count = rc.z * rc.w;
      }
      row[q] = clamp(row[q] + sigma * rsqrt((float)count) * (k ? g1 : g0), 0.0f, 255.0f);
    }
  }
}
