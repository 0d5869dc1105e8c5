// No implicit contraction of a*b+c: the dense and sparse paths must round alike, so
// fused multiply-adds are written out as fma() where wanted.
#pragma OPENCL FP_CONTRACT OFF

// Philox4x32-10: the same generator as host/scene/philox.h (see there for the layout).
// key = (seed lo, seed hi); counter = (element, stream, scenario lo, scenario hi).

inline uint4 philox4x32_10(uint4 c, uint2 k) {
  for (int r = 0; r < 10; ++r) {
    const uint lo0 = 0xD2511F53u * c.x, hi0 = mul_hi(0xD2511F53u, c.x);
    const uint lo1 = 0xCD9E8D57u * c.z, hi1 = mul_hi(0xCD9E8D57u, c.z);
    c = (uint4)(hi1 ^ c.y ^ k.x, lo1, hi0 ^ c.w ^ k.y, lo0);
    k += (uint2)(0x9E3779B9u, 0xBB67AE85u);
  }
  return c;
}

inline uint4 draw(uint2 seed, ulong index, uint stream, uint element) {
  return philox4x32_10((uint4)(element, stream, (uint)index, (uint)(index >> 32)), seed);
}

// The global index of a batch's scenario i: the batch's first index plus i, or where the
// batch is not contiguous (a run whose raw grid is drawn runs each grid's scenarios
// together), its index table's entry; a null table is a contiguous batch.
inline ulong scenario_index(global const ulong* indices, uint first_lo, uint first_hi, uint i) {
  return indices ? indices[i] : upsample(first_hi, first_lo) + i;
}

inline float uniform24(uint r) { return (float)(r >> 8) * (1.0f / 16777216.0f); }
inline uint below(uint r, uint n) { return mul_hi(r, n); }

// A knob drawn per scenario (docs/model/drawn-knobs.md): element e of PS_STREAM_KNOB_DRAW,
// lo + (hi - lo) uniform24(word 0) for a real knob (in the precision of lo and hi), or
// lo + below(word 0, hi - lo + 1) for a whole one; lo where the range is one value.
inline float __attribute__((overloadable)) knob_draw(float lo, float hi, uint2 seed, ulong index, uint e) {
  return hi > lo ? lo + (hi - lo) * uniform24(draw(seed, index, PS_STREAM_KNOB_DRAW, e).x) : lo;
}
#if defined(PRECISION_FP64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
inline double __attribute__((overloadable)) knob_draw(double lo, double hi, uint2 seed, ulong index, uint e) {
  return hi > lo ? lo + (hi - lo) * (double)uniform24(draw(seed, index, PS_STREAM_KNOB_DRAW, e).x) : lo;
}
#endif
inline int __attribute__((overloadable)) knob_draw(int lo, int hi, uint2 seed, ulong index, uint e) {
  return hi > lo ? lo + (int)below(draw(seed, index, PS_STREAM_KNOB_DRAW, e).x, (uint)(hi - lo) + 1u) : lo;
}
// Scenario index's value of the drawn knob e (PS_DRAWN_*) from its range in d (PsDrawn, which
// the host fills from the knobs' declarations): a real knob's at the parameters' precision
// (the physics model's preal, the pixel noise's param), a whole one's.
inline PS_PARAM drawn_real(global const PsDrawn* d, uint e, uint2 seed, ulong index) {
  return knob_draw(d->lo[e], d->hi[e], seed, index, e);
}
inline int drawn_whole(global const PsDrawn* d, uint e, uint2 seed, ulong index) {
  return knob_draw((int)d->lo[e], (int)d->hi[e], seed, index, e);
}
// A view's drawn ranges: the head of its parameters (PsPhys::drawn), in either model.
inline global const PsDrawn* phys_drawn(global const PS_PARAM* phys) { return &((global const PsPhys*)phys)->drawn; }
