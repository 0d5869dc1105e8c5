// Block averaging (thesis 5.6): means of n x n blocks of both MMW views, then of each
// region's rectangle. Sums are exact integers; partial edge blocks average the pixels
// they hold.

// A mean of 8-bit pixels: whole part by integer division, remainder in float, so a flat
// area's mean is exact even when -cl-fast-relaxed-math makes float division approximate
// (host/sink/folder_reader.cpp computes the same expression). Clamped to the pixel range.
inline float mean_of(uint sum, int count) {
  const uint q = sum / (uint)count, r = sum % (uint)count;
  return clamp((float)q + (float)r / (float)count, 0.0f, 255.0f);
}

// One work-item per (scenario, view, block). Features row: upper blocks, lower blocks,
// region means.
kernel void pool_blocks(global const uchar* upper, global const uchar* lower, uint n, int W, int H, int block,
                        int bx_count, int by_count, int row_len, global float* features) {
  const size_t gid = get_global_id(0);
  const int per_view = bx_count * by_count;
  const uint i = (uint)(gid / (size_t)(2 * per_view));
  if (i >= n) return;
  const int rem = (int)(gid % (size_t)(2 * per_view));
  const int view = rem / per_view, b = rem % per_view;
  const int x0 = (b % bx_count) * block, y0 = (b / bx_count) * block;
  const int x1 = min(x0 + block, W), y1 = min(y0 + block, H);
  global const uchar* img = (view ? lower : upper) + (size_t)i * W * H;
  uint sum = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) sum += img[y * W + x];
  features[(size_t)i * row_len + rem] = mean_of(sum, (x1 - x0) * (y1 - y0));
}

// One work-item per (scenario, region). rects: int4 (x, y, w, h) in the region's MMW view.
kernel void pool_regions(global const uchar* upper, global const uchar* lower, uint n, int W, int H,
                         global const int4* rects, int offset, int row_len, global float* features) {
  const size_t gid = get_global_id(0);
  const uint i = (uint)(gid / 13);
  if (i >= n) return;
  const int r = (int)(gid % 13);
  const int4 rc = rects[r];
  global const uchar* img = (r < 6 ? upper : lower) + (size_t)i * W * H;
  uint sum = 0;
  for (int y = rc.y; y < rc.y + rc.w; ++y)
    for (int x = rc.x; x < rc.x + rc.z; ++x) sum += img[y * W + x];
  features[(size_t)i * row_len + offset + r] = mean_of(sum, rc.z * rc.w);
}

// ---------------------------------------------------------------------------------
// Sparse block averaging for features-only runs (no per-pixel noise): blocks that no
// object touches keep the subject's precomputed base means, and an object's effect on
// the blocks and regions it touches comes from a table made once per run
// (footprint_deltas). Only pixels where two objects' footprints overlap are rendered
// per scenario. Every value is the dense path's to the bit: the same blend() and noise
// arithmetic, integer sums, and the same final division.
//
// Footprint record per (variant, region), 16 ints:
//   0 sprite x0, 1 sprite y0, 2 sprite w, 3 sprite h, 4 sprite atlas offset,
//   5 tile x0, 6 tile y0, 7..10 footprint x0, y0, x1, y1 (clipped, exclusive ends),
//   11 block x0, 12 block y0, 13 blocks wide, 14 blocks high, 15 delta table offset.
#define FP_LEN 16

inline int block_count(int bx, int by, int block, int W, int H) {
  return (min(bx * block + block, W) - bx * block) * (min(by * block + block, H) - by * block);
}

// Base means and sums of every subject: one work-item per (subject, feature), features
// as in a row (upper blocks, lower blocks, regions).
kernel void base_features(global const uchar* atlas, global const int* bases, global const int4* rects, int S,
                          int W, int H, int block, int bx_count, int by_count, int row_len, global int* sums,
                          global float* means) {
  const int g = (int)get_global_id(0);
  if (g >= S * row_len) return;
  const int s = g / row_len, f = g % row_len, per_view = bx_count * by_count;
  uint sum = 0;
  int count;
  if (f < 2 * per_view) {
    const int view = f / per_view, b = f % per_view;
    const int x0 = (b % bx_count) * block, y0 = (b / bx_count) * block;
    const int x1 = min(x0 + block, W), y1 = min(y0 + block, H);
    global const uchar* img = atlas + bases[s * 3 + view];
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) sum += img[y * W + x];
    count = (x1 - x0) * (y1 - y0);
  } else {
    const int r = f - 2 * per_view;
    const int4 rc = rects[r];
    global const uchar* img = atlas + bases[s * 3 + (r < 6 ? 0 : 1)];
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
  const int sx = x - fp[0], sy = y - fp[1];
  if (sx >= 0 && sy >= 0 && sx < fp[2] && sy < fp[3]) {
    const int o = fp[4] + (sy * fp[2] + sx) * 2;
    v = blend(v, atlas[o], atlas[o + 1], alpha);
  }
  if (use_noise) {
    real n = real_zero();
    const int tx = x - fp[5], ty = y - fp[6];
    if (tx >= 0 && ty >= 0 && tx < tile && ty < tile) n = noise_acc(n, atlas[tile_offset + ty * tile + tx]);
    v = add_noise(v, gain, n);
  }
  return to_pixel(v);
}

// One work-item per (variant, region, subject, pattern): the sums of (pixel - base)
// over each block of the footprint and over each region.
kernel void footprint_deltas(global const uchar* atlas, global const int* bases, global const int* fps,
                             global const int* noise_offsets, global const float* noise_gains,
                             global const int4* rects, int combos, int S, int P, int W, int block, param alpha,
                             int tile, int use_noise, global int* deltas, global int* region_deltas) {
  const int g = (int)get_global_id(0);
  if (g >= combos) return;
  const int p = g % P, s = (g / P) % S, vr = g / (P * S), r = vr % 13;
  global const int* fp = fps + vr * FP_LEN;
  const int view = r < 6 ? 0 : 1;
  global const uchar* base = atlas + bases[s * 3 + view];
  global int* d = deltas + fp[15] + (s * P + p) * fp[13] * fp[14];
  for (int k = 0; k < fp[13] * fp[14]; ++k) d[k] = 0;
  int reg[13];
  for (int k = 0; k < 13; ++k) reg[k] = 0;
  const int toff = noise_offsets[p];
  const float gain = noise_gains[p];
  for (int y = fp[8]; y < fp[10]; ++y)
    for (int x = fp[7]; x < fp[9]; ++x) {
      const uchar b = base[y * W + x];
      const int diff = (int)single_pixel(atlas, fp, b, x, y, W, alpha, tile, toff, gain, use_noise) - (int)b;
      if (diff == 0) continue;
      d[(y / block - fp[12]) * fp[13] + (x / block - fp[11])] += diff;
      for (int q = view ? 6 : 0; q < (view ? 13 : 6); ++q) {
        const int4 rc = rects[q];
        if (x >= rc.x && y >= rc.y && x < rc.x + rc.z && y < rc.y + rc.w) reg[q] += diff;
      }
    }
  for (int k = 0; k < 13; ++k) region_deltas[g * 13 + k] = reg[k];
}

inline int in_rect(int x, int y, global const int* fp) {
  return x >= fp[7] && y >= fp[8] && x < fp[9] && y < fp[10];
}
inline int in_blocks(int bx, int by, global const int* fp) {
  return bx >= fp[11] && by >= fp[12] && bx < fp[11] + fp[13] && by < fp[12] + fp[14];
}

// One work-item per scenario: a features row from base means, table deltas and the
// overlap pixels rendered here.
kernel void features_sparse(global const uchar* atlas, global const int* bases, global const int* fps,
                            global const int* deltas, global const int* region_deltas, global const int* base_sums,
                            global const float* base_means, global const int* noise_offsets,
                            global const float* noise_gains, global const int4* rects, global const uchar* subject,
                            global const short* objects, uint n, int S, int P, int W, int H, int block,
                            int bx_count, int by_count, param alpha, int tile, int use_noise, uint2 seed,
                            uint2 first, int row_len, global float* features) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const int s = subject[i], per_view = bx_count * by_count;
  global const short* objs = objects + (size_t)i * 13;
  global float* row = features + (size_t)i * row_len;
  global const float* bm = base_means + s * row_len;
  global const int* bs = base_sums + s * row_len;
  for (int f = 0; f < row_len; ++f) row[f] = bm[f];
  int p = 0;
  if (use_noise) p = (int)below(draw(seed, upsample(first.y, first.x) + i, STREAM_NOISE_PATTERN, 0u).x, (uint)P);
  const int toff = noise_offsets[p];
  const float gain = noise_gains[p];

  int reg[13];
  for (int r = 0; r < 13; ++r) reg[r] = bs[2 * per_view + r];
  int touched_regions = 0;

  for (int view = 0; view < 2; ++view) {
    const int r0 = view ? 6 : 0, r1 = view ? 13 : 6;
    global const int* fp[7];
    int comb[7];
    int cnt = 0;
    for (int r = r0; r < r1; ++r) {
      const int v = objs[r];
      if (v < 0) continue;
      fp[cnt] = fps + (v * 13 + r) * FP_LEN;
      comb[cnt] = (v * 13 + r) * S * P + s * P + p;
      ++cnt;
    }
    if (cnt == 0) continue;
    touched_regions = 1;
    global float* vrow = row + view * per_view;
    global const int* vbs = bs + view * per_view;
    // Touched blocks hold integer sums (exact in float below 2^24) until the division.
    for (int k = 0; k < cnt; ++k)
      for (int by = fp[k][12]; by < fp[k][12] + fp[k][14]; ++by)
        for (int bx = fp[k][11]; bx < fp[k][11] + fp[k][13]; ++bx) {
          int seen = 0;
          for (int j = 0; j < k; ++j) seen |= in_blocks(bx, by, fp[j]);
          if (!seen) vrow[by * bx_count + bx] = (float)vbs[by * bx_count + bx];
        }
    for (int k = 0; k < cnt; ++k) {
      global const int* d = deltas + fp[k][15] + (s * P + p) * fp[k][13] * fp[k][14];
      for (int by = 0; by < fp[k][14]; ++by)
        for (int bx = 0; bx < fp[k][13]; ++bx)
          vrow[(fp[k][12] + by) * bx_count + fp[k][11] + bx] += (float)d[by * fp[k][13] + bx];
      for (int r = r0; r < r1; ++r) reg[r] += region_deltas[comb[k] * 13 + r];
    }
    // Where footprints overlap, the table's single-object values are wrong: replace
    // their sum by the pixel rendered with every object, as the dense kernel does.
    global const uchar* base = atlas + bases[s * 3 + view];
    for (int a = 0; a < cnt; ++a)
      for (int b = a + 1; b < cnt; ++b) {
        const int x0 = max(fp[a][7], fp[b][7]), y0 = max(fp[a][8], fp[b][8]);
        const int x1 = min(fp[a][9], fp[b][9]), y1 = min(fp[a][10], fp[b][10]);
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            int earlier = 0;  // a pixel in several overlaps is corrected once
            for (int a2 = 0; a2 <= a && !earlier; ++a2)
              for (int b2 = a2 + 1; b2 < (a2 == a ? b : cnt) && !earlier; ++b2)
                earlier = in_rect(x, y, fp[a2]) && in_rect(x, y, fp[b2]);
            if (earlier) continue;
            const uchar bp = base[y * W + x];
            real v = from_pixel(bp), nsum = real_zero();
            int singles = 0;
            for (int k = 0; k < cnt; ++k) {
              if (!in_rect(x, y, fp[k])) continue;
              singles += (int)single_pixel(atlas, fp[k], bp, x, y, W, alpha, tile, toff, gain, use_noise) - (int)bp;
              const int sx = x - fp[k][0], sy = y - fp[k][1];
              if (sx >= 0 && sy >= 0 && sx < fp[k][2] && sy < fp[k][3]) {
                const int o = fp[k][4] + (sy * fp[k][2] + sx) * 2;
                v = blend(v, atlas[o], atlas[o + 1], alpha);
              }
            }
            if (use_noise) {
              for (int k = 0; k < cnt; ++k) {
                const int tx = x - fp[k][5], ty = y - fp[k][6];
                if (tx >= 0 && ty >= 0 && tx < tile && ty < tile) nsum = noise_acc(nsum, atlas[toff + ty * tile + tx]);
              }
              v = add_noise(v, gain, nsum);
            }
            const int corr = (int)to_pixel(v) - (int)bp - singles;
            if (corr == 0) continue;
            vrow[(y / block) * bx_count + x / block] += (float)corr;
            for (int r = r0; r < r1; ++r) {
              const int4 rc = rects[r];
              if (x >= rc.x && y >= rc.y && x < rc.x + rc.z && y < rc.y + rc.w) reg[r] += corr;
            }
          }
      }
    for (int k = 0; k < cnt; ++k)
      for (int by = fp[k][12]; by < fp[k][12] + fp[k][14]; ++by)
        for (int bx = fp[k][11]; bx < fp[k][11] + fp[k][13]; ++bx) {
          int seen = 0;
          for (int j = 0; j < k; ++j) seen |= in_blocks(bx, by, fp[j]);
          if (!seen) vrow[by * bx_count + bx] = mean_of((uint)vrow[by * bx_count + bx], block_count(bx, by, block, W, H));
        }
  }
  if (touched_regions)
    for (int r = 0; r < 13; ++r) {
      const int4 rc = rects[r];
      row[2 * per_view + r] = mean_of((uint)reg[r], rc.z * rc.w);
    }
}

#define STREAM_BLOCK_NOISE 4u

// The block-mean noise model (tier "fast", features-only runs with pixel noise): rather
// than drawing sigma * N(0,1) for every pixel, each mean over c pixels gets one draw of
// N(0, sigma^2 / c), clipped to the pixel range. Rounding and clipping of single pixels
// are not modelled; tradeoff measures what that costs. One work-item per scenario.
kernel void analytic_noise(global float* features, global const int4* rects, uint n, int W, int H, int block,
                           int bx_count, int by_count, int row_len, float sigma, uint2 seed, uint2 first) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const ulong index = upsample(first.y, first.x) + i;
  const int per_view = bx_count * by_count;
  global float* row = features + (size_t)i * row_len;
  for (int f = 0; f < row_len; f += 2) {
    const uint4 r = draw(seed, index, STREAM_BLOCK_NOISE, (uint)f);
    const float2 g = gauss2(r.x, r.y);
    for (int k = 0; k < 2 && f + k < row_len; ++k) {
      const int q = f + k;
      int count;
      if (q < 2 * per_view) {
        const int b = q % per_view;
        count = block_count(b % bx_count, b / bx_count, block, W, H);
      } else {
        const int4 rc = rects[q - 2 * per_view];
        count = rc.z * rc.w;
      }
      row[q] = clamp(row[q] + sigma * rsqrt((float)count) * (k ? g.y : g.x), 0.0f, 255.0f);
    }
  }
}
