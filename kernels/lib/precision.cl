// 16 bytes at any address in one vector load or store. PoCL lowers vstore16 to 16 byte
// stores; a store through an align(1) vector type is one unaligned vector store.
typedef uchar16 __attribute__((aligned(1))) uchar16_any;
inline uchar16 load16(global const uchar* p) { return *(global const uchar16_any*)p; }
inline void store16(uchar16 v, global uchar* p) { *(global uchar16_any*)p = v; }
// The same for 16 floats (vload16 and vstore16 of floats are 16 scalar moves too).
typedef float16 __attribute__((aligned(4))) float16_any;
#define LOADF16(SPACE, p) (*(SPACE const float16_any*)(p))
#define STOREF16(SPACE, v, p) (*(SPACE float16_any*)(p) = (v))
// 64 bytes at any address in one store: Zen 4 stores a narrowed vector (vpmovdb to
// memory) slowly, so runs of levels are joined in registers first.
typedef uchar uchar32_ __attribute__((ext_vector_type(32)));
typedef uchar uchar64_ __attribute__((ext_vector_type(64)));
typedef uchar64_ __attribute__((aligned(1))) uchar64_any;
#define LANES16 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15
#define LANES32 LANES16, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31
#define LANES64                                                                                                        \
  LANES32, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56, 57, 58, \
      59, 60, 61, 62, 63
inline void store64(uchar16 a, uchar16 b, uchar16 c, uchar16 d, global uchar* p) {
  const uchar32_ ab = __builtin_shufflevector(a, b, LANES32), cd = __builtin_shufflevector(c, d, LANES32);
  *(global uchar64_any*)p = __builtin_shufflevector(ab, cd, LANES64);
}

// Round half to even (rint) as one instruction (vrndscaleps) where clang has the builtin;
// PoCL's own rint on vectors is generic integer code. Exact either way, so the same values.
#if __has_builtin(__builtin_elementwise_roundeven)
#define RINT(x) __builtin_elementwise_roundeven(x)
#else
#define RINT(x) rint(x)
#endif

// The arithmetic of a pixel value, chosen at build time (the fidelity tiers):
//   default          fp32
//   PRECISION_FP64   fp64, the reference's formulas (tier "exact")
//   PRECISION_FIXED  8.8 fixed point in integers (tier "fast")
// Every stage works through these helpers, so the dense and sparse paths of one build
// round alike.

#if defined(PRECISION_FP64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double real;
typedef double greal;  // Gaussian draws
typedef double2 greal2;
typedef double param;  // alpha and sigma as the catalogue and command line give them
inline real from_pixel(uchar b) { return (real)b; }
// The reference's form: a s + (1 - a) v, a = alpha coverage / 255.
inline real blend(real v, uchar value, uchar coverage, param alpha) {
  const real a = (real)alpha * (real)coverage / 255.0;
  return a * (real)value + (1.0 - a) * v;
}
// A sub-pixel layer: premultiplied value pv and coverage c (0..1) from bilinear sampling.
inline real blend_frac(real v, greal pv, greal c, param alpha) {
  return (1.0 - (real)alpha * c) * v + (real)alpha * pv;
}
inline real noise_acc(real n, uchar t) { return n + ((real)t - 128.0); }
inline real add_noise(real v, float gain, real n) { return v + (real)gain * n; }
inline real add_gauss(real v, param sigma, greal g) { return v + (real)sigma * g; }
inline uchar to_pixel(real v) { return (uchar)clamp(floor(v + 0.5), 0.0, 255.0); }
inline real real_zero(void) { return 0.0; }

#elif defined(PRECISION_FIXED)
typedef int real;  // value * 256
typedef float greal;
typedef float2 greal2;
typedef float param;
// A pixel's arithmetic over element type R (int or int16; F, U: its float and byte types),
// one text for the scalar helpers (S empty) and the 16-lane ones (S 16).
#define PIXEL_OPS(R, F, U, S)                                                                              \
  inline R from_pixel##S(U b) { return convert_##R(b) << 8; }                                             \
  inline R blend##S(R v, U value, U coverage, param alpha) {                                              \
    const R a = convert_##R(alpha * convert_##F(coverage) * (256.0f / 255.0f) + 0.5f); /* 0..256 */      \
    return v + ((a * ((convert_##R(value) << 8) - v)) >> 8);                                              \
  }                                                                                                       \
  inline R noise_acc##S(R n, U t) { return n + (convert_##R(t) - 128); }                                  \
  inline R add_noise##S(R v, float gain, R n) { return v + (int)rint(gain * 256.0f) * n; }                \
  inline R add_gauss##S(R v, param sigma, F g) { return v + convert_##R(RINT(sigma * g * 256.0f)); }      \
  inline U to_pixel##S(R v) { return convert_##U(clamp((v + 128) >> 8, 0, 255)); }                       \
  inline R real##S##_zero(void) { return (R)(0); }
PIXEL_OPS(int, float, uchar, )
inline real blend_frac(real v, greal pv, greal c, param alpha) {
  return (int)rint((1.0f - alpha * c) * (float)v + alpha * pv * 256.0f);
}

#else
typedef float real;
typedef float greal;
typedef float2 greal2;
typedef float param;
// A pixel's arithmetic over element type R (float or float16; U its byte type), one text
// for the scalar helpers (S empty) and the 16-lane ones (S 16). blend: v + a (s - v),
// a = alpha coverage / 255, one rounding in the fused multiply-add. to_pixel: floor(v +
// 0.5) clamped, as the reference; clamping first and then truncating gives the same byte
// for every v and needs no floor.
#define PIXEL_OPS(R, U, S)                                                                                  \
  inline R from_pixel##S(U b) { return convert_##R(b); }                                                  \
  inline R blend##S(R v, U value, U coverage, param alpha) {                                              \
    const R a = alpha * convert_##R(coverage) / 255.0f;                                                   \
    return fma(a, convert_##R(value) - v, v);                                                             \
  }                                                                                                       \
  inline R noise_acc##S(R n, U t) { return n + (convert_##R(t) - 128.0f); }                               \
  inline R add_noise##S(R v, float gain, R n) { return v + gain * n; }                                    \
  inline R add_gauss##S(R v, param sigma, R g) { return fma((R)(sigma), g, v); }                          \
  inline U to_pixel##S(R v) { return convert_##U(clamp(v + 0.5f, 0.0f, 255.0f)); }                       \
  inline R real##S##_zero(void) { return (R)(0.0f); }
PIXEL_OPS(float, uchar, )
inline real blend_frac(real v, greal pv, greal c, param alpha) { return (1.0f - alpha * c) * v + alpha * pv; }
#endif

// The same arithmetic on 16 pixels at once, element for element (so bit for bit), for the
// vector render path. fp64 (tier "exact") renders pixel by pixel.
#if !defined(PRECISION_FP64)
#define VECTOR_RENDER 1
#if defined(PRECISION_FIXED)
typedef int16 real16;
PIXEL_OPS(int16, float16, uchar16, 16)
#else
typedef float16 real16;
PIXEL_OPS(float16, uchar16, 16)
#endif
#endif

// The physics model's values (kelvin, gray before rounding): double in fp64 builds, else
// float, in every tier (8.8 fixed point cannot hold a temperature to a tenth of a gray).
#if defined(PRECISION_FP64)
typedef double preal;
#else
typedef float preal;
#endif
