// Stage "netd" (physics model): the MMW camera's sensor noise over L.frames raw frames
// averaged, each frame's draw Gaussian with the NETD as standard deviation (kelvin): one
// table Gaussian per raw pixel and frame from the counter generator (frame 0 from
// PS_STREAM_RAW_NOISE, frame k from PS_STREAM_FRAME_NOISE + k; PS_GAUSS_ELEMENT;
// kernels/sensor_noise.cl). Under the fast approximation the host passes one frame of
// NETD / sqrt(frames).
inline uint frame_stream(int k) { return k == 0 ? PS_STREAM_RAW_NOISE : PS_STREAM_FRAME_NOISE + (uint)k; }

// Scenario index's MMW noise where the NETD or the frames are drawn per scenario (host:
// netd_at, frames_at): NETD in [lo, hi] (PS_STREAM_KNOB_DRAW, PS_DRAWN_NETD, real), frames
// in [flo, fhi] (PS_DRAWN_FRAMES, whole); *frames frames of the returned sd each, or under
// the block-mean noise model (as_one) one of NETD / sqrt(frames).
inline preal mmw_noise_drawn(preal lo, preal hi, int flo, int fhi, bool as_one, uint2 seed, ulong index,
                             int* frames) {
  const preal netd = knob_draw(lo, hi, seed, index, PS_DRAWN_NETD);
  const int f = knob_draw(flo, fhi, seed, index, PS_DRAWN_FRAMES);
  *frames = as_one ? 1 : f;
  return as_one ? netd / sqrt((preal)f) : netd / (preal)f;
}

// Scenario index's MMW noise from the view's parameters: *frames frames (the launch's
// kframes where nothing is drawn) of the returned sd each.
inline preal mmw_noise_of(global const param* phys, int kframes, uint2 seed, ulong index, int* frames) {
  const preal lo = (preal)phys[PS_PHYS_NETD], hi = (preal)phys[PS_PHYS_NETD_HI];
  const int flo = (int)phys[PS_PHYS_FRAMES_LO], fhi = (int)phys[PS_PHYS_FRAMES_HI];
  if (hi <= lo && fhi <= flo) {
    *frames = kframes;
    return lo / (preal)kframes;
  }
  return mmw_noise_drawn(lo, hi, flo, fhi, phys[PS_PHYS_FRAMES_AS_ONE] != 0, seed, index, frames);
}

// The fast tier's draws (PS_FLAG_FAST_DRAWS): sensor_noise.cl's Irwin-Hall draws (ih_cell,
// ih128) of the table Gaussians' cells and streams.

// Adds sd times the draws of cells [0, cells) of `stream` to v: table Gaussians, or with
// `fast` the fast tier's draws. The stage kernels' noise (stage_netd's rows go cell by cell).
inline void noise_cells(global preal* restrict v, int cells, preal sd, uint2 seed, ulong index, uint stream, int view,
                        global const param* table, bool fast) {
  if (!fast) {
    gauss_cells_global(v, cells, sd, true, seed, index, stream, view, table);
    return;
  }
#if defined(PRECISION_FP64)
  for (int p = 0; p < cells; ++p) v[p] = v[p] + sd * ih_cell(seed, index, stream, view, p);
#else
  for (int p = 0; p < cells; p += 128) {
    float16 g[8];
    ih128(seed, index, stream, view, p >> 7, g);
    for (int j = 0; j < 8; ++j) {
      const int q = p + 16 * j;
      if (q + 16 <= cells) {
        STOREF16(global, LOADF16(global, v + q) + sd * g[j], v + q);
      } else {
        float t[16];
        vstore16(g[j], 0, t);
        for (int k = q; k < cells; ++k) v[k] = v[k] + sd * t[k - q];
        break;
      }
    }
  }
#endif
}

kernel void stage_netd(VIEW_STAGE_ARGS) {
  RAW_STAGE_ROW;
  int frames;
  const preal sd = mmw_noise_of(phys, L.frames, seed, index, &frames);
  if (sd <= 0) return;
  const bool fast = L.flags & PS_FLAG_FAST_DRAWS;
  for (int k = 0; k < frames; ++k)
    for (int c = 0; c < L.raw_width; ++c)
      r[c] += sd * (fast ? ih_cell(seed, index, frame_stream(k), L.view, j * L.raw_width + c)
                         : gauss_cell(seed, index, frame_stream(k), L.view, j * L.raw_width + c, phys + L.phys_gauss));
}

#if !defined(PRECISION_FP64)
// The counters of block b of a view's table Gaussians in `stream` (gauss128's), as 64-bit
// lanes for PHILOX16_ROUND.
#define GAUSS_BLOCK_COUNTERS(c0, c1, c2, c3, view, b, stream, index)                                          \
  ulong16 c0 = convert_ulong16(((uint)(view) << PS_PIXEL_NOISE_VIEW_SHIFT) |                                  \
                               ((uint)(16 * (b)) + (uint16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))); \
  ulong16 c1 = (ulong16)(stream), c2 = (ulong16)((uint)(index)), c3 = (ulong16)((uint)((index) >> 32))

// Two blocks of 128 table Gaussians (gauss128's values): block ba of stream sa into g and
// block bb of stream sb into h, their Philox rounds interleaved so that one block's
// multiplies fill the other's wait (one block alone is a chain of 10 dependent rounds).
__attribute__((always_inline)) inline void gauss128x2(uint2 seed, ulong index, int view, uint sa, int ba, uint sb,
                                                      int bb, global const float* table, float16* g, float16* h) {
  GAUSS_BLOCK_COUNTERS(a0, a1, a2, a3, view, ba, sa, index);
  GAUSS_BLOCK_COUNTERS(b0, b1, b2, b3, view, bb, sb, index);
  uint2 k = seed;
#pragma unroll
  for (int r = 0; r < 10; ++r) {
    PHILOX16_ROUND(a0, a1, a2, a3, k);
    PHILOX16_ROUND(b0, b1, b2, b3, k);
    k += (uint2)(0x9E3779B9u, 0xBB67AE85u);
  }
  const uint16 wa[4] = {convert_uint16(a0), convert_uint16(a1), convert_uint16(a2), convert_uint16(a3)};
  const uint16 wb[4] = {convert_uint16(b0), convert_uint16(b1), convert_uint16(b2), convert_uint16(b3)};
#pragma unroll
  for (int w = 0; w < 4; ++w) {
    const uint16 alo = PS_GAUSS_INDEX(wa[w], 0), ahi = PS_GAUSS_INDEX(wa[w], 16);
    const uint16 blo = PS_GAUSS_INDEX(wb[w], 0), bhi = PS_GAUSS_INDEX(wb[w], 16);
    g[2 * w] = GATHER16(table, alo);
    g[2 * w + 1] = GATHER16(table, ahi);
    h[2 * w] = GATHER16(table, blo);
    h[2 * w + 1] = GATHER16(table, bhi);
  }
}
#endif

// The netd stage over a scenario's whole raw grid v (physics_raw): L.frames frames of sd
// each added to every cell, frame after frame, as stage_netd's sums. fp32 builds hold a
// block of 128 cells in registers through all the frames and draw two frames' table
// Gaussians at once; the fast draws (one frame under the fast tier) go as noise_cells.
inline void netd_frames(global preal* restrict v, int cells, preal sd, int frames, uint2 seed, ulong index, int view,
                        global const param* table, bool fast) {
#if defined(PRECISION_FP64)
  for (int k = 0; k < frames; ++k) noise_cells(v, cells, sd, seed, index, frame_stream(k), view, table, fast);
#else
  if (fast) {
    for (int k = 0; k < frames; ++k) noise_cells(v, cells, sd, seed, index, frame_stream(k), view, table, true);
    return;
  }
  for (int p = 0; p < cells; p += 128) {
    const int n = min(cells - p, 128);
    float16 acc[8];
#pragma unroll
    for (int j = 0; j < 8; ++j) {
      if (16 * j + 16 <= n) {
        acc[j] = LOADF16(global, v + p + 16 * j);
      } else {
        float t[16];
        for (int q = 0; q < 16; ++q) t[q] = 16 * j + q < n ? v[p + 16 * j + q] : 0.0f;
        acc[j] = vload16(0, t);
      }
    }
    int k = 0;
    for (; k + 2 <= frames; k += 2) {
      float16 g[8], h[8];
      gauss128x2(seed, index, view, frame_stream(k), p >> 7, frame_stream(k + 1), p >> 7, table, g, h);
#pragma unroll
      for (int j = 0; j < 8; ++j) acc[j] = (acc[j] + sd * g[j]) + sd * h[j];
    }
    if (k < frames) {
      float16 g[8];
      gauss128(seed, index, frame_stream(k), view, p >> 7, table, g);
#pragma unroll
      for (int j = 0; j < 8; ++j) acc[j] = acc[j] + sd * g[j];
    }
#pragma unroll
    for (int j = 0; j < 8; ++j) {
      if (16 * j + 16 <= n) {
        STOREF16(global, acc[j], v + p + 16 * j);
      } else {
        float t[16];
        vstore16(acc[j], 0, t);
        for (int q = 0; 16 * j + q < n && q < 16; ++q) v[p + 16 * j + q] = t[q];
      }
    }
  }
#endif
}
