// Helpers (kernels/lib/): the counter generator's draws for every stage and fast path. The
// per-pixel noise's Box-Muller pairs (its ln and sincos as polynomials), the table
// Gaussians of the physics model, the fast tier's Irwin-Hall draws, each for one cell and
// for 16 lanes from one text, and their 128-cell blocks.
//
// The per-pixel noise (stage sensor_noise, render_view): one Philox draw feeds a Box-Muller pair (pixels 2k, 2k+1 of the view): u1 = 1 - r.x/2^32 (24 bits),
// u2 = r.y/2^32, g = sqrt(-2 ln u1) (cos, sin)(2 pi u2).
//
// fp32 and fixed16 builds compute ln and sincos with polynomials, defined once below for
// one value and for 16 (PoCL's own log, sin and cos are slow scalar library calls):
//   ln x, x in [2^-24, 1]: x = m 2^e with m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s),
//     s = (m - 1) / (m + 1), |s| <= 0.1716, series to s^9 (truncation < 3e-9 relative);
//   sincos(2 pi u): t = u - rint(u), quadrant k = rint(4 t), a = 2 pi (t - k/4) in
//     [-pi/4, pi/4], sin to a^9 and cos to a^10 (truncation < 3e-9), then rotated by k.
// Against double-precision libm the draws differ by a few float ulps (tests/stages_test.cpp
// and the tier tolerances hold the pixels). fp64 builds (tier "exact") use libm.

#define GAUSS_POLY(F, I)                                                                                      \
  inline F __attribute__((overloadable)) ln_poly(F x) {                                                     \
    const I bits = as_##I(x);                                                                               \
    I e = ((bits >> 23) & 0xff) - 127;                                                                      \
    F m = as_##F((bits & 0x7fffff) | 0x3f800000);                                                           \
    const I big = m > (F)(1.41421356f);                                                                     \
    m = select(m, m * 0.5f, big);                                                                           \
    e = select(e, e + 1, big);                                                                              \
    const F s = (m - 1.0f) / (m + 1.0f), s2 = s * s;                                                        \
    const F p = 2.0f * s *                                                                                  \
                (1.0f + s2 * (0.33333333f + s2 * (0.2f + s2 * (0.14285714f + s2 * 0.11111111f))));         \
    return convert_##F(e) * 0.69314718f + p;                                                                \
  }                                                                                                         \
  inline void __attribute__((overloadable)) sincos_turns(F u, F* sn, F* cs) {                               \
    const F t = u - RINT(u);                                                                                \
    const F kf = RINT(t * 4.0f);                                                                            \
    const F a = (t - kf * 0.25f) * 6.2831853f, a2 = a * a;                                                  \
    const F s = a * (1.0f + a2 * (-0.16666667f + a2 * (8.3333333e-3f + a2 * (-1.9841270e-4f +               \
                                                                                 a2 * 2.7557319e-6f))));    \
    const F c = 1.0f + a2 * (-0.5f + a2 * (4.1666667e-2f + a2 * (-1.3888889e-3f +                           \
                                                               a2 * (2.4801587e-5f + a2 * -2.7557319e-7f)))); \
    const I k = convert_##I(kf) & 3;                                                                        \
    *cs = select(select(select(c, -s, k == 1), -c, k == 2), s, k == 3);                                     \
    *sn = select(select(select(s, c, k == 1), -s, k == 2), -c, k == 3);                                     \
  }
GAUSS_POLY(float, int)
GAUSS_POLY(float16, int16)

// Box-Muller of Philox words r0, r1 (one pair, or 16 side by side): the draws rad cos and
// rad sin into *g0 and *g1.
#define BOX_MULLER(F, U)                                                                        \
  inline void __attribute__((overloadable)) box_muller(U r0, U r1, F* g0, F* g1) {            \
    const F u1 = 1.0f - convert_##F(r0 >> 8) * (1.0f / 16777216.0f);                           \
    const F u2 = convert_##F(r1 >> 8) * (1.0f / 16777216.0f);                                   \
    const F rad = sqrt(-2.0f * ln_poly(u1));                                                    \
    F s, c;                                                                                     \
    sincos_turns(u2, &s, &c);                                                                   \
    *g0 = rad * c;                                                                              \
    *g1 = rad * s;                                                                              \
  }
BOX_MULLER(float, uint)
BOX_MULLER(float16, uint16)

// Philox4x32-10 of 16 counters at once (kernels/lib/philox.cl, lane by lane). Each 32-bit word
// lives in a 64-bit lane, so one vpmuludq gives 8 whole products: hi = p >> 32, and lo is p
// itself, whose high half only ever reaches a multiply (which masks it off) or an xor into
// a word whose high half is masked or dropped in turn. Per round of 16 lanes that is 4
// multiplies, 4 shifts and 4 xors, where 32-bit lanes took 6 multiplies and 2 two-source
// permutes. Unrolled, the compiler keeps the round keys scalar, multiplies the words that
// are the same in every lane (stream, scenario) once in the first two rounds, and drops
// the last round's products that no caller reads.
#define PHILOX16_ROUND(c0, c1, c2, c3, k)                                                              \
  {                                                                                                   \
    const ulong16 p0 = (c0 & 0xFFFFFFFFul) * 0xD2511F53ul, p1 = (c2 & 0xFFFFFFFFul) * 0xCD9E8D57ul; \
    c0 = (p1 >> 32) ^ c1 ^ (ulong)k.x;                                                                \
    c1 = p1;                                                                                          \
    c2 = (p0 >> 32) ^ c3 ^ (ulong)k.y;                                                                \
    c3 = p0;                                                                                          \
  }
__attribute__((always_inline)) inline void philox16(uint16* c0, uint16* c1, uint16* c2, uint16* c3, uint2 k) {
  ulong16 d0 = convert_ulong16(*c0), d1 = convert_ulong16(*c1), d2 = convert_ulong16(*c2), d3 = convert_ulong16(*c3);
#pragma unroll
  for (int r = 0; r < 10; ++r) {
    PHILOX16_ROUND(d0, d1, d2, d3, k);
    k += (uint2)(0x9E3779B9u, 0xBB67AE85u);
  }
  *c0 = convert_uint16(d0);
  *c1 = convert_uint16(d1);
  *c2 = convert_uint16(d2);
  *c3 = convert_uint16(d3);
}
// Two sets of 16 counters, their rounds interleaved so that one set's multiplies fill the
// other's wait; only words 0 and 1 (what Box-Muller reads) are written back.
__attribute__((always_inline)) inline void philox16x2(uint16* a, uint16* b, uint2 k) {
  ulong16 a0 = convert_ulong16(a[0]), a1 = convert_ulong16(a[1]), a2 = convert_ulong16(a[2]), a3 = convert_ulong16(a[3]);
  ulong16 b0 = convert_ulong16(b[0]), b1 = convert_ulong16(b[1]), b2 = convert_ulong16(b[2]), b3 = convert_ulong16(b[3]);
#pragma unroll
  for (int r = 0; r < 10; ++r) {
    PHILOX16_ROUND(a0, a1, a2, a3, k);
    PHILOX16_ROUND(b0, b1, b2, b3, k);
    k += (uint2)(0x9E3779B9u, 0xBB67AE85u);
  }
  a[0] = convert_uint16(a0);
  a[1] = convert_uint16(a1);
  b[0] = convert_uint16(b0);
  b[1] = convert_uint16(b1);
}

#if defined(PRECISION_FP64)
inline greal2 gauss_pair_of(uint2 seed, ulong index, uint stream, int view, int pair) {
  const uint4 r = draw(seed, index, stream, ((uint)view << PS_PIXEL_NOISE_VIEW_SHIFT) | (uint)pair);
  const greal u1 = (greal)1 - (greal)(r.x >> 8) * ((greal)1 / (greal)16777216);
  const greal u2 = (greal)(r.y >> 8) * ((greal)1 / (greal)16777216);
  const greal rad = sqrt((greal)-2 * log(u1));
  const greal th = (greal)6.283185307179586 * u2;
  return (greal2)(rad * cos(th), rad * sin(th));
}
#else
inline greal2 gauss_pair_of(uint2 seed, ulong index, uint stream, int view, int pair) {
  const uint4 r = draw(seed, index, stream, ((uint)view << PS_PIXEL_NOISE_VIEW_SHIFT) | (uint)pair);
  float g0, g1;
  box_muller(r.x, r.y, &g0, &g1);
  return (float2)(g0, g1);
}

// Box-Muller of 16 Philox outputs (words r0, r1): the draws of 32 pixels, interleaved,
// the first 16 pixels in *g0 and the next 16 in *g1.
__attribute__((always_inline)) inline void box_muller16(uint16 r0, uint16 r1, float16* g0, float16* g1) {
  float16 c, s;
  box_muller(r0, r1, &c, &s);
  *g0 = shuffle2(c, s, (uint16)(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23));
  *g1 = shuffle2(c, s, (uint16)(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31));
}

// The counters of elements first .. first + 15 of a view in a stream: 16 Box-Muller pairs,
// or the 16 draws of a block of 128 cells in the table Gaussians' layout (first = 16 b).
inline void counters16(uint16* c, ulong index, uint stream, int view, int first) {
  c[0] = ((uint)view << PS_PIXEL_NOISE_VIEW_SHIFT) |
         ((uint)first + (uint16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
  c[1] = (uint16)(stream);
  c[2] = (uint16)((uint)index);
  c[3] = (uint16)((uint)(index >> 32));
}

// The draws of pixels 2 pair .. 2 pair + 31 of a stream: 16 Box-Muller pairs, interleaved,
// the first 16 pixels in *g0 and the next 16 in *g1.
__attribute__((always_inline)) inline void gauss32(uint2 seed, ulong index, uint stream, int view, int pair,
                                                   float16* g0, float16* g1) {
  uint16 c[4];
  counters16(c, index, stream, view, pair);
  philox16(&c[0], &c[1], &c[2], &c[3], seed);
  box_muller16(c[0], c[1], g0, g1);
}

// The draws of pixels 2 pair .. 2 pair + 63, 16 at a time in g[0..3].
__attribute__((always_inline)) inline void gauss64(uint2 seed, ulong index, uint stream, int view, int pair,
                                                   float16* g) {
  uint16 a[4], b[4];
  counters16(a, index, stream, view, pair);
  counters16(b, index, stream, view, pair + 16);
  philox16x2(a, b, seed);
  box_muller16(a[0], a[1], &g[0], &g[1]);
  box_muller16(b[0], b[1], &g[2], &g[3]);
}
#endif

// The physics model's sensor noise (kernels/shared.h, PS_GAUSS_ELEMENT): a table Gaussian
// per cell, eight cells to one draw of the generator where Box-Muller takes two, and no
// log or sincos. The table (phys + L.tables.gauss, built on the host) holds the 4,096
// equally likely values Phi^-1((k + 1/2) / 4096): |g| <= 3.67, sd 1 - 1.6e-4.
// Cell p's word of its draw in the table Gaussians' layout (PS_GAUSS_ELEMENT, PS_GAUSS_WORD).
inline uint cell_word(uint2 seed, ulong index, uint stream, int view, int p) {
  const uint4 r = draw(seed, index, stream, PS_GAUSS_ELEMENT(view, p));
  const int w = PS_GAUSS_WORD(p);
  return w == 0 ? r.x : w == 1 ? r.y : w == 2 ? r.z : r.w;
}
inline preal gauss_cell(uint2 seed, ulong index, uint stream, int view, int p, global const param* table) {
  return (preal)table[PS_GAUSS_INDEX(cell_word(seed, index, stream, view, p), p)];
}

#if !defined(PRECISION_FP64)
#define GATHER16(t, k)                                                                                    \
  (float16)(t[k.s0], t[k.s1], t[k.s2], t[k.s3], t[k.s4], t[k.s5], t[k.s6], t[k.s7], t[k.s8], t[k.s9], \
            t[k.sa], t[k.sb], t[k.sc], t[k.sd], t[k.se], t[k.sf])
// Cells 128 b .. 128 b + 127 of a view's field: g[j] holds cells 128 b + 16 j .. + 15.
__attribute__((always_inline)) inline void gauss128(uint2 seed, ulong index, uint stream, int view, int b,
                                                    global const float* table, float16* g) {
  uint16 c[4];
  counters16(c, index, stream, view, 16 * b);
  philox16(&c[0], &c[1], &c[2], &c[3], seed);
#pragma unroll
  for (int w = 0; w < 4; ++w) {
    const uint16 lo = PS_GAUSS_INDEX(c[w], 0), hi = PS_GAUSS_INDEX(c[w], 16);  // cells 16 b + .., + 16
    g[2 * w] = GATHER16(table, lo);
    g[2 * w + 1] = GATHER16(table, hi);
  }
}
#endif

// The Irwin-Hall draw (noise_draw irwin-hall, the fast tier's; kernels/contract.h, PS_IH_*),
// of both models: cell p's 16-bit half in the table Gaussians' layout, its two bytes summed,
// s, and d = s - 255 taken through the odd quintic. Eight cells to one Philox draw where
// Box-Muller takes two, no log, root or sincos, and no table to gather from. d is exact in
// integers, so the float steps are one multiply and the written fma()s, alike for 1 and 16.
// The thesis model's pixel noise draws from PS_STREAM_PIXEL_NOISE_FAST (ih_pixel), the
// physics cameras' NETD from their table Gaussians' streams (netd.cl, ir_surface*.cl).
// ih_shape of one d and ih_shape16 of 16 (F the element type, P its scalar, I the ints).
#define IH_SHAPE(F, P, I, S)                                                                         \
  inline F ih_shape##S(I d) {                                                                      \
    const F t = convert_##F(d) * ((P)1 / (P)255), t2 = t * t;                                      \
    return t * fma(t2, fma(t2, (F)((P)PS_IH_C5), (F)((P)PS_IH_C3)), (F)((P)PS_IH_C1));             \
  }
#if defined(PRECISION_FP64)
IH_SHAPE(double, double, int, )
#else
IH_SHAPE(float, float, int, )
IH_SHAPE(float16, float, int16, 16)
#endif
// Both 16-bit halves' byte sums of a word (each at most 510), in its halves: one masked
// add for a cell (ih_cell) and for 16 words (ih128).
#define IH_BYTE_SUMS(w) (((w)&0x00ff00ffu) + (((w) >> 8) & 0x00ff00ffu))
inline greal ih_cell(uint2 seed, ulong index, uint stream, int view, int p) {
  const uint s = IH_BYTE_SUMS(cell_word(seed, index, stream, view, p)) >> PS_GAUSS_SHIFT(p);
  return ih_shape((int)(s & 0xffffu) - 255);
}
inline greal ih_pixel(uint2 seed, ulong index, int view, int p) {
  return ih_cell(seed, index, PS_STREAM_PIXEL_NOISE_FAST, view, p);
}
#if !defined(PRECISION_FP64)
// The Irwin-Hall draws of cells 128 b .. 128 b + 127 of a view's field in `stream`: g[j]
// holds cells 128 b + 16 j .. + 15.
__attribute__((always_inline)) inline void ih128(uint2 seed, ulong index, uint stream, int view, int b,
                                                 float16* g) {
  uint16 c[4];
  counters16(c, index, stream, view, 16 * b);
  philox16(&c[0], &c[1], &c[2], &c[3], seed);
#pragma unroll
  for (int w = 0; w < 4; ++w) {
    const int16 s = as_int16(IH_BYTE_SUMS(c[w]));
    g[2 * w] = ih_shape16((s & 0xffff) - 255);
    g[2 * w + 1] = ih_shape16((s >> 16) - 255);
  }
}
#endif

// Adds sd times draws of cells [0, cells) to v (one scenario's field), or, where
// !accumulate, writes them there: NAME_SPACE, with DRAW1 a cell p's draw and DRAW128 (fp32)
// cells 128 (p >> 7) .. + 127 into float16 g[8]. gauss_cells_global and gauss_cells_private
// draw table Gaussians, ih_cells_global the fast tier's Irwin-Hall draws.
#if defined(PRECISION_FP64)
#define DRAW_CELLS(NAME, SPACE, DRAW1, DRAW128)                                                                    \
  inline void NAME##_##SPACE(SPACE preal* restrict v, int cells, preal sd, bool accumulate, uint2 seed,          \
                             ulong index, uint stream, int view, global const param* table) {                    \
    for (int p = 0; p < cells; ++p) v[p] = (accumulate ? v[p] : 0) + sd * DRAW1;                                 \
  }
#else
#define DRAW_CELLS(NAME, SPACE, DRAW1, DRAW128)                                                                    \
  inline void NAME##_##SPACE(SPACE preal* restrict v, int cells, preal sd, bool accumulate, uint2 seed,          \
                             ulong index, uint stream, int view, global const param* table) {                    \
    for (int p = 0; p < cells; p += 128) {                                                                       \
      float16 g[8];                                                                                              \
      DRAW128;                                                                                                   \
      for (int j = 0; j < 8; ++j) {                                                                              \
        const int q = p + 16 * j;                                                                                \
        if (q + 16 <= cells) {                                                                                   \
          STOREF16(SPACE, accumulate ? LOADF16(SPACE, v + q) + sd * g[j] : sd * g[j], v + q);                    \
        } else {                                                                                                 \
          float t[16];                                                                                           \
          vstore16(g[j], 0, t);                                                                                  \
          for (int k = q; k < cells; ++k) v[k] = (accumulate ? v[k] : 0) + sd * t[k - q];                        \
          break;                                                                                                 \
        }                                                                                                        \
      }                                                                                                          \
    }                                                                                                            \
  }
#endif
#define GAUSS_CELLS(SPACE)                                                         \
  DRAW_CELLS(gauss_cells, SPACE, gauss_cell(seed, index, stream, view, p, table), \
             gauss128(seed, index, stream, view, p >> 7, table, g))
GAUSS_CELLS(global)
GAUSS_CELLS(private)

// The Box-Muller pair of draws `pair` of a view's per-pixel noise stream.
inline greal2 gauss_pair(uint2 seed, ulong index, int view, int pair) {
  return gauss_pair_of(seed, index, PS_STREAM_PIXEL_NOISE, view, pair);
}

// Scenario index's pixel noise sigma (the knob pixel_noise; host: drawn_knob_at), from the
// view's parameters: the knob's, or where drawn per scenario its draw.
inline param pixel_sigma_of(global const param* phys, uint2 seed, ulong index) {
  return drawn_real(phys_drawn(phys), PS_DRAWN_PIXEL_NOISE, seed, index);
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

// Adds sd times the draws of cells [0, cells) of `stream` to v: table Gaussians, or with
// `fast` the fast tier's (PS_FLAG_FAST_DRAWS: the Irwin-Hall draws of the same cells and
// streams, ih_cell and ih128). The stage kernels' noise (stage_netd's rows go cell by cell).
DRAW_CELLS(ih_cells, global, ih_cell(seed, index, stream, view, p), ih128(seed, index, stream, view, p >> 7, g))
inline void noise_cells(global preal* restrict v, int cells, preal sd, uint2 seed, ulong index, uint stream, int view,
                        global const param* table, bool fast) {
  if (fast)
    ih_cells_global(v, cells, sd, true, seed, index, stream, view, table);
  else
    gauss_cells_global(v, cells, sd, true, seed, index, stream, view, table);
}
