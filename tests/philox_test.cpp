// The counter generator against its specification (docs/model/determinism.md): the
// published Random123 known-answer vectors and hand-computed draws, applied to the
// reference's C++ (scene/philox.h, backend/reference/draws.h) and, through the OpenCL
// runtime, to the kernels' own implementation (kernels/lib/philox.cl, kernels/sensor_noise.cl).
#include "scene/philox.h"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include "backend/compare.h"
#include "backend/opencl/gauss_table.h"
#include "backend/opencl/kernels.h"
#include "backend/opencl/noise_draws.h"
#include "backend/opencl/runtime.h"
#include "backend/reference/draws.h"
#include "base/embedded.h"
#include "plan/tolerance.h"
#include "scene/catalogue.h"

namespace portalsim {
namespace {

struct Kat {
  Philox4 ctr;
  std::array<uint32_t, 2> key;
  Philox4 expected;
};
// Random123's known answers for philox4x32_10. The first three are those of its
// kat_vectors file that kat_main checks; the rest are every "philox4x32 10" row of the
// longer examples/kat_vectors table (made by Random123's gentests.py), as copied in
// github.com/girving/random123-manual, examples/kat_vectors at commit 61e8479.
// clang-format off
constexpr Kat kKat[] = {
    {{0, 0, 0, 0}, {0, 0}, {0x6627e8d5, 0xe169c58d, 0xbc57ac4c, 0x9b00dbd8}},
    {{0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff}, {0xffffffff, 0xffffffff}, {0x408f276d, 0x41c83b0e, 0xa20bc7c6, 0x6d5451fd}},
    {{0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, {0xa4093822, 0x299f31d0}, {0xd16cfe09, 0x94fdcceb, 0x5001e420, 0x24126ea1}},
    {{0x00000001, 0x00000000, 0x00000000, 0x00000000}, {0x00000001, 0x00000000}, {0xac08141b, 0xdfc5ccbe, 0x79c07a47, 0xa7f66093}},
    {{0x00000000, 0x00000001, 0x00000000, 0x00000000}, {0x00000001, 0x00000000}, {0x833ff8dc, 0x225c963c, 0x232b88b3, 0x0b334b07}},
    {{0x00000000, 0x00000000, 0x00000001, 0x00000000}, {0x00000001, 0x00000000}, {0x07071c12, 0x428264b6, 0x3909104b, 0x6da2bda2}},
    {{0x00000000, 0x00000000, 0x00000000, 0x00000001}, {0x00000001, 0x00000000}, {0x127bee41, 0x1e047488, 0x48842b20, 0x0a393496}},
    {{0x00000000, 0xffffffff, 0x00000000, 0x00000000}, {0x00000001, 0x00000000}, {0x04e2eae1, 0x463cc999, 0xe7786310, 0x65b3dc49}},
    {{0x00000000, 0x80000000, 0x00000000, 0x00000000}, {0x00000001, 0x00000000}, {0x34a4d61d, 0x340e4017, 0xf6945830, 0xe9f52b96}},
    {{0x00000000, 0x00000000, 0xffffffff, 0x00000000}, {0x00000001, 0x00000000}, {0xfb0905e2, 0x78378790, 0xca37926b, 0xcdf58cfa}},
    {{0x00000000, 0x00000000, 0x80000000, 0x00000000}, {0x00000001, 0x00000000}, {0xf2e15c7d, 0x3fedcd99, 0x90046f6c, 0x6657f0ca}},
    {{0x00000000, 0x00000000, 0x00000000, 0xffffffff}, {0x00000001, 0x00000000}, {0xf50c9398, 0xb36cdab2, 0x436bdc89, 0xcc49431b}},
    {{0x00000000, 0x00000000, 0x00000000, 0x80000000}, {0x00000001, 0x00000000}, {0xdde26e4e, 0x17666f3b, 0xfc1f5b3a, 0x83ac805d}},
    {{0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, {0x00000001, 0x00000000}, {0x38527b8f, 0xfad9a48c, 0x20e675c0, 0xf2fea26a}},
    {{0xa4093822, 0x299f31d0, 0x082efa98, 0xec4e6c89}, {0x00000001, 0x00000000}, {0xfb9877f8, 0x482895e2, 0x60b01453, 0x198ea67b}},
    {{0x452821e6, 0x38d01377, 0xbe5466cf, 0x34e90c6c}, {0x00000001, 0x00000000}, {0xf7b7fa0a, 0x8d970e2c, 0x205c9c76, 0x83b16ce5}},
    {{0x00000001, 0x00000000, 0x00000000, 0x00000000}, {0x00000000, 0x00000001}, {0xccf3076a, 0x6306f434, 0xbea71965, 0xd96fe48a}},
    {{0x00000000, 0x00000001, 0x00000000, 0x00000000}, {0x00000000, 0x00000001}, {0x532f1322, 0x36c890fb, 0x6504b937, 0x07bbfef7}},
    {{0x00000000, 0x00000000, 0x00000001, 0x00000000}, {0x00000000, 0x00000001}, {0x7f6c13ff, 0x114b2447, 0x0550eced, 0xea1fc805}},
    {{0x00000000, 0x00000000, 0x00000000, 0x00000001}, {0x00000000, 0x00000001}, {0x96b27e8c, 0x28826d0f, 0x66d958ef, 0x081509dc}},
    {{0x00000000, 0xffffffff, 0x00000000, 0x00000000}, {0x00000000, 0x00000001}, {0x00e94a67, 0x3524f44e, 0x22995230, 0xbb54df1e}},
    {{0x00000000, 0x80000000, 0x00000000, 0x00000000}, {0x00000000, 0x00000001}, {0xce1afc4e, 0x4fbf97a1, 0x6110bee9, 0xa559be2f}},
    {{0x00000000, 0x00000000, 0xffffffff, 0x00000000}, {0x00000000, 0x00000001}, {0x576241af, 0xd3b45bee, 0x619bd94d, 0x15dd8793}},
    {{0x00000000, 0x00000000, 0x80000000, 0x00000000}, {0x00000000, 0x00000001}, {0xd9da65af, 0xeced57ba, 0xc34d2661, 0x91fe931f}},
    {{0x00000000, 0x00000000, 0x00000000, 0xffffffff}, {0x00000000, 0x00000001}, {0x36241728, 0x4d42c858, 0xfea737d6, 0x49f40347}},
    {{0x00000000, 0x00000000, 0x00000000, 0x80000000}, {0x00000000, 0x00000001}, {0x0436a39b, 0x31be9efa, 0x6abd0c76, 0xe7a68f83}},
    {{0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, {0x00000000, 0x00000001}, {0x126514c3, 0xd1898b69, 0xda2707b3, 0x6e6fb436}},
    {{0xa4093822, 0x299f31d0, 0x082efa98, 0xec4e6c89}, {0x00000000, 0x00000001}, {0x1c28fa3f, 0x8c5bf977, 0xbb989783, 0x0c1a3737}},
    {{0x452821e6, 0x38d01377, 0xbe5466cf, 0x34e90c6c}, {0x00000000, 0x00000001}, {0xac87a8c1, 0xf240abdb, 0xadd6c012, 0x68a32a78}},
    {{0x00000001, 0x00000000, 0x00000000, 0x00000000}, {0x00000000, 0xffffffff}, {0x473ab778, 0x330bacc0, 0xacd5fc9a, 0x5ede76b3}},
    {{0x00000000, 0x00000001, 0x00000000, 0x00000000}, {0x00000000, 0xffffffff}, {0xcdfbd51c, 0xcaae5f2e, 0x10739cfc, 0x79e95162}},
    {{0x00000000, 0x00000000, 0x00000001, 0x00000000}, {0x00000000, 0xffffffff}, {0x6c4b0e80, 0x357e5a94, 0x3255445d, 0x6f433f0b}},
    {{0x00000000, 0x00000000, 0x00000000, 0x00000001}, {0x00000000, 0xffffffff}, {0x5c4ecd0c, 0x64c12cf9, 0x8f9fb4c8, 0x40c4a01f}},
    {{0x00000000, 0xffffffff, 0x00000000, 0x00000000}, {0x00000000, 0xffffffff}, {0x5f9c47aa, 0x19861d86, 0xff2be81d, 0x4c7db17e}},
    {{0x00000000, 0x80000000, 0x00000000, 0x00000000}, {0x00000000, 0xffffffff}, {0x715a87cf, 0xf966a7f0, 0x3e6dd95f, 0xe884e2fd}},
    {{0x00000000, 0x00000000, 0xffffffff, 0x00000000}, {0x00000000, 0xffffffff}, {0x07678411, 0x9e524307, 0xba634e67, 0x94ee8cb7}},
    {{0x00000000, 0x00000000, 0x80000000, 0x00000000}, {0x00000000, 0xffffffff}, {0xb6f48e28, 0xf2fa9414, 0x00b64f66, 0x4810cdb4}},
    {{0x00000000, 0x00000000, 0x00000000, 0xffffffff}, {0x00000000, 0xffffffff}, {0x9f18bb20, 0x62161056, 0x7ea8c028, 0x4c01fc6e}},
    {{0x00000000, 0x00000000, 0x00000000, 0x80000000}, {0x00000000, 0xffffffff}, {0x2a460458, 0x0a2709e5, 0x47bc9115, 0x0f96d8af}},
    {{0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, {0x00000000, 0xffffffff}, {0x08f7720c, 0x845ee9e0, 0x502ccd3d, 0xa9a00e27}},
    {{0xa4093822, 0x299f31d0, 0x082efa98, 0xec4e6c89}, {0x00000000, 0xffffffff}, {0x9fcce05d, 0x837d3f3c, 0x5cdf3e61, 0xdb2544c0}},
    {{0x452821e6, 0x38d01377, 0xbe5466cf, 0x34e90c6c}, {0x00000000, 0xffffffff}, {0x72ce44b3, 0xb44f9b78, 0x49af0267, 0x726813ac}},
    {{0x00000001, 0x00000000, 0x00000000, 0x00000000}, {0x00000000, 0x80000000}, {0xe29b9f84, 0x2903d316, 0x42a1f56f, 0x1ad02eab}},
    {{0x00000000, 0x00000001, 0x00000000, 0x00000000}, {0x00000000, 0x80000000}, {0x94f419f8, 0x1116c316, 0x99f2fa30, 0xbc048ad6}},
    {{0x00000000, 0x00000000, 0x00000001, 0x00000000}, {0x00000000, 0x80000000}, {0x488b0258, 0x9eea6420, 0xafe7062e, 0x768f5637}},
    {{0x00000000, 0x00000000, 0x00000000, 0x00000001}, {0x00000000, 0x80000000}, {0xdbec6d70, 0x69cea528, 0xf7e22262, 0x2e9f3e8f}},
    {{0x00000000, 0xffffffff, 0x00000000, 0x00000000}, {0x00000000, 0x80000000}, {0x905ee550, 0xc7520e9a, 0x9af9d0ad, 0x69b97e98}},
    {{0x00000000, 0x80000000, 0x00000000, 0x00000000}, {0x00000000, 0x80000000}, {0x1b89d963, 0x0defe9af, 0x60c9d3fb, 0x3cfae97d}},
    {{0x00000000, 0x00000000, 0xffffffff, 0x00000000}, {0x00000000, 0x80000000}, {0x601b5460, 0xfe29678b, 0x54510a02, 0xc72ed094}},
    {{0x00000000, 0x00000000, 0x80000000, 0x00000000}, {0x00000000, 0x80000000}, {0xae56ca02, 0x7609ba67, 0x25abd7df, 0x46ce39a3}},
    {{0x00000000, 0x00000000, 0x00000000, 0xffffffff}, {0x00000000, 0x80000000}, {0x09812238, 0x47b8470d, 0x3e0d0a26, 0x92d96c9a}},
    {{0x00000000, 0x00000000, 0x00000000, 0x80000000}, {0x00000000, 0x80000000}, {0xf7a0b371, 0xe51dc93d, 0x56ce135d, 0x1d4b5580}},
    {{0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, {0x00000000, 0x80000000}, {0x63675d2c, 0x422d7c4d, 0x3145d30d, 0x3bce33a4}},
    {{0xa4093822, 0x299f31d0, 0x082efa98, 0xec4e6c89}, {0x00000000, 0x80000000}, {0xaa74e81c, 0xc9ddb97b, 0x2c2cd881, 0x9390c78d}},
    {{0x452821e6, 0x38d01377, 0xbe5466cf, 0x34e90c6c}, {0x00000000, 0x80000000}, {0x94ca5566, 0x14924b2f, 0x28214292, 0x59faeaee}},
};
// clang-format on

// The physics model's table Gaussians and the thesis's Box-Muller pixel noise, worked out
// by hand from docs/model/determinism.md (outside the project, in Python with
// scipy.special.ndtri): the element, the word, its 16-bit half, the 12 bits k, then
// Phi^-1((k + 1/2) / 4096); and the two words of a pixel pair's draw, then Box-Muller.
struct TableCase {
  uint64_t seed, index;
  uint32_t stream;
  int view, cell;
  uint32_t element;
  int word, half, k;
  double g;
};
constexpr TableCase kTableCases[] = {
    {0x0ull, 0x0ull, 6, 0, 0, 0x0u, 0, 0, 2976, 0.6028163640348647},
    {0x1352505ull, 0x7ull, 6, 0, 17, 0x1u, 0, 1, 2579, 0.3312197333654088},
    {0x7ull, 0x75bcd15ull, 7, 2, 40, 0x20000008u, 1, 0, 1997, -0.030909395630494614},
    {0xdeadbeefcafef00dull, 0x10000000003ull, 9, 1, 77, 0x1000000du, 2, 0, 1225, -0.5267190971156902},
    {0x5ull, 0x2ull, 6, 1, 127, 0x1000000fu, 3, 1, 1684, -0.22431813554248808},
    {0x5ull, 0x2ull, 6, 1, 133, 0x10000015u, 0, 0, 241, -1.5635643101093275},
    {0x63ull, 0x200000000ull, 7, 2, 1000, 0x20000078u, 3, 0, 1102, -0.6153401946121357},
    {0x3039ull, 0x2aull, 9, 0, 50001, 0x1861u, 2, 1, 2150, 0.06276809547639602},
};
struct PixelCase {
  uint64_t seed, index;
  int view, pixel;
  uint32_t w0, w1;
  double g;
};
constexpr PixelCase kPixelCases[] = {
    {0x0ull, 0x0ull, 0, 0, 0xd1299bf0u, 0xd4c6e697u, 0.8996638054329474},
    {0x0ull, 0x0ull, 0, 1, 0xd1299bf0u, 0xd4c6e697u, -1.608599549329078},
    {0x1352505ull, 0x5ull, 1, 4097, 0x70503c4fu, 0x39bccf8au, 1.062078819006085},
    {0x4dull, 0x800000000ull, 2, 19998, 0xf1f3861fu, 0xdb3942a0u, 1.4927541291256141},
    {0xffffffffffffffffull, 0xcull, 0, 7, 0x89c23a61u, 0xe93112b5u, -0.6600223559870463},
};

// One buffer of `v` for a kernel to read.
template <class T>
cl::Buffer input(OpenCLRuntime& rt, const std::vector<T>& v) {
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                    const_cast<T*>(v.data()));
}

// Builds the kernel program with `test_kernels` after it, and runs `name` over n work-items
// with `args` (buffers or scalars, in order); returns the program for further kernels.
template <class... Args>
void run(OpenCLRuntime& rt, const char* test_kernels, const char* name, size_t n, const Args&... args) {
  cl::Program prog(rt.context(), std::string(embedded::kernel_program) + test_kernels);
  prog.build(
      ("-cl-std=CL1.2 " + opencl::build_options(Fidelity{}, opencl::KernelCounts::of(default_catalogue()))).c_str());
  cl::Kernel k(prog, name);
  cl_uint i = 0;
  (k.setArg(i++, args), ...);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n));
  rt.queue().finish();
}

template <class T>
std::vector<T> read(OpenCLRuntime& rt, const cl::Buffer& b, size_t n) {
  std::vector<T> v(n);
  rt.queue().enqueueReadBuffer(b, CL_TRUE, 0, n * sizeof(T), v.data());
  return v;
}

// The seed, index, view and pixel of each pixel case, as the test kernels take them.
struct PixelColumns {
  std::vector<cl_ulong> seed, index;
  std::vector<cl_int> view, pixel;
  template <class Case, size_t N>
  explicit PixelColumns(const Case (&cases)[N]) {
    for (const Case& c : cases) {
      seed.push_back(c.seed);
      index.push_back(c.index);
      view.push_back(c.view);
      pixel.push_back(c.pixel);
    }
  }
};

}  // namespace

TEST(Philox, KnownAnswerVectors) {
  for (const Kat& v : kKat)
    EXPECT_EQ(philox4x32_10(v.ctr, v.key), v.expected) << std::hex << v.ctr[0] << " " << v.key[1];
}

TEST(Philox, KernelKnownAnswerVectors) {
  OpenCLRuntime rt;
  std::vector<cl_uint4> ctr;
  std::vector<cl_uint2> key;
  for (const Kat& v : kKat) {
    ctr.push_back({{v.ctr[0], v.ctr[1], v.ctr[2], v.ctr[3]}});
    key.push_back({{v.key[0], v.key[1]}});
  }
  const size_t n = ctr.size();
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(cl_uint4));
  run(rt, R"(
kernel void kat(global const uint4* ctr, global const uint2* key, global uint4* out) {
  const size_t i = get_global_id(0);
  out[i] = philox4x32_10(ctr[i], key[i]);
})",
      "kat", n, input(rt, ctr), input(rt, key), out);
  const std::vector<cl_uint4> got = read<cl_uint4>(rt, out, n);
  for (size_t i = 0; i < n; ++i)
    for (int w = 0; w < 4; ++w) EXPECT_EQ(got[i].s[w], kKat[i].expected[w]) << "vector " << i << " word " << w;
}

TEST(Philox, TableGaussianHandComputed) {
  for (const TableCase& c : kTableCases) {
    SCOPED_TRACE("cell " + std::to_string(c.cell));
    // The element and word the specification names hold the bits k.
    const uint32_t word = draw(c.seed, c.index, c.stream, c.element)[c.word];
    EXPECT_EQ(((c.half ? word >> 16 : word & 0xffffu) >> 4), uint32_t(c.k));
    EXPECT_NEAR(reference::table_gaussian(c.seed, c.index, c.stream, c.view, c.cell), c.g, 1e-12);
  }
  // The kernels' gauss_cell: with a table of k itself it returns the bits it chose; with
  // the host's table of quantiles, the Gaussian (a float).
  OpenCLRuntime rt;
  std::vector<cl_ulong> seed, index;
  std::vector<cl_uint> stream;
  std::vector<cl_int> view, cell;
  for (const TableCase& c : kTableCases) {
    seed.push_back(c.seed);
    index.push_back(c.index);
    stream.push_back(c.stream);
    view.push_back(c.view);
    cell.push_back(c.cell);
  }
  const size_t n = seed.size();
  std::vector<float> identity(PS_GAUSS_TABLE), quantiles(gauss_table().begin(), gauss_table().end());
  for (size_t k = 0; k < identity.size(); ++k) identity[k] = float(k);
  for (const auto* table : {&identity, &quantiles}) {
    cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(float));
    run(rt, R"(
kernel void cells(global const ulong* seed, global const ulong* index, global const uint* stream,
                  global const int* view, global const int* cell, global const param* table, global float* out) {
  const size_t i = get_global_id(0);
  out[i] = (float)gauss_cell((uint2)((uint)seed[i], (uint)(seed[i] >> 32)), index[i], stream[i], view[i], cell[i], table);
})",
        "cells", n, input(rt, seed), input(rt, index), input(rt, stream), input(rt, view), input(rt, cell),
        input(rt, *table), out);
    const std::vector<float> got = read<float>(rt, out, n);
    for (size_t i = 0; i < n; ++i) {
      if (table == &identity)
        EXPECT_EQ(got[i], float(kTableCases[i].k)) << "cell " << kTableCases[i].cell;
      else
        EXPECT_NEAR(got[i], kTableCases[i].g, 1e-6) << "cell " << kTableCases[i].cell;
    }
  }
}

TEST(Philox, PixelGaussianHandComputed) {
  OpenCLRuntime rt;
  for (const PixelCase& c : kPixelCases) {
    SCOPED_TRACE("pixel " + std::to_string(c.pixel));
    const Philox4 r = draw(c.seed, c.index, kStreamPixelNoise, (uint32_t(c.view) << 28) | uint32_t(c.pixel / 2));
    EXPECT_EQ(r[0], c.w0);
    EXPECT_EQ(r[1], c.w1);
    EXPECT_NEAR(reference::pixel_gaussian(c.seed, c.index, c.view, c.pixel), c.g, 1e-12);
  }
  // The kernels' Box-Muller (box_muller) on their own draw of the pair: float against the
  // hand-computed double.
  const PixelColumns a(kPixelCases);
  const size_t n = a.seed.size();
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(float));
  run(rt, R"(
kernel void pixels(global const ulong* seed, global const ulong* index, global const int* view,
                   global const int* pixel, global float* out) {
  const size_t i = get_global_id(0);
  const uint4 r = draw((uint2)((uint)seed[i], (uint)(seed[i] >> 32)), index[i], PS_STREAM_PIXEL_NOISE,
                       ((uint)view[i] << PS_PIXEL_NOISE_VIEW_SHIFT) | (uint)(pixel[i] / 2));
  float g0, g1;
  box_muller(r.x, r.y, &g0, &g1);
  out[i] = pixel[i] % 2 == 0 ? g0 : g1;
})",
      "pixels", n, input(rt, a.seed), input(rt, a.index), input(rt, a.view), input(rt, a.pixel), out);
  const std::vector<float> got = read<float>(rt, out, n);
  for (size_t i = 0; i < n; ++i) EXPECT_NEAR(got[i], kPixelCases[i].g, 2e-5) << "pixel " << kPixelCases[i].pixel;
}

// The Irwin-Hall pixel draw (noise_draw irwin-hall), worked by hand from determinism.md
// outside the project (Python: its own Philox4x32-10, checked against the Box-Muller table's
// words, then the element, word, half, byte sum s and the quintic in double).
struct IrwinHallCase {
  uint64_t seed, index;
  int view, pixel;
  uint32_t element;
  int word, half;
  uint32_t w;  // the word
  int s;       // its half's two bytes summed
  double g;
};
constexpr IrwinHallCase kIrwinHallCases[] = {
    {0x0ull, 0x0ull, 0, 0, 0x0u, 0, 0, 0xdcd5b333u, 230, -0.231958019446},
    {0x1352505ull, 0x7ull, 0, 17, 0x1u, 0, 1, 0xeb39d7e5u, 292, 0.341969775996},
    {0x7ull, 0x75bcd15ull, 2, 40, 0x20000008u, 1, 0, 0x7a33ae4au, 248, -0.065151888865},
    {0xdeadbeefcafef00dull, 0x10000000003ull, 1, 77, 0x1000000du, 2, 0, 0xb6b9f7d5u, 460, 2.083790849101},
    {0x5ull, 0x2ull, 1, 127, 0x1000000fu, 3, 1, 0xf70b3718u, 258, 0.027928425553},
    {0x5ull, 0x2ull, 1, 133, 0x10000015u, 0, 0, 0x80958ed5u, 355, 0.896466028029},
    {0x63ull, 0x200000000ull, 2, 1000, 0x20000078u, 3, 0, 0xfa141d12u, 47, -2.138631262265},
    {0xffffffffffffffffull, 0xcull, 0, 39999, 0x138fu, 1, 1, 0x254efa91u, 115, -1.253780953433},
};

TEST(Philox, IrwinHallHandComputed) {
  OpenCLRuntime rt;
  for (const IrwinHallCase& c : kIrwinHallCases) {
    SCOPED_TRACE("pixel " + std::to_string(c.pixel));
    const uint32_t w = draw(c.seed, c.index, kStreamPixelNoiseFast, c.element)[c.word];
    EXPECT_EQ(w, c.w);
    const uint32_t h = c.half ? w >> 16 : w & 0xffffu;
    EXPECT_EQ(int(h & 0xffu) + int(h >> 8), c.s);
    EXPECT_NEAR(reference::pixel_irwin_hall(c.seed, c.index, c.view, c.pixel), c.g, 1e-11);
  }
  // The kernels' ih_pixel, and ih128 (the fused path's 128 at once) at the same pixel.
  const PixelColumns a(kIrwinHallCases);
  const size_t n = a.seed.size();
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, 2 * n * sizeof(float));
  run(rt, R"(
kernel void ih(global const ulong* seed, global const ulong* index, global const int* view,
               global const int* pixel, global float* out) {
  const size_t i = get_global_id(0);
  const uint2 key = (uint2)((uint)seed[i], (uint)(seed[i] >> 32));
  out[2 * i] = ih_pixel(key, index[i], view[i], pixel[i]);
  float16 g[8];
  ih128(key, index[i], PS_STREAM_PIXEL_NOISE_FAST, view[i], pixel[i] >> 7, g);
  float t[128];
  for (int j = 0; j < 8; ++j) vstore16(g[j], j, t);
  out[2 * i + 1] = t[pixel[i] & 127];
})",
      "ih", n, input(rt, a.seed), input(rt, a.index), input(rt, a.view), input(rt, a.pixel), out);
  const std::vector<float> got = read<float>(rt, out, 2 * n);
  for (size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(got[2 * i], kIrwinHallCases[i].g, kIrwinHallDrawAbs) << "pixel " << kIrwinHallCases[i].pixel;
    EXPECT_EQ(got[2 * i + 1], got[2 * i]) << "ih128 against ih_pixel, pixel " << kIrwinHallCases[i].pixel;
  }
}

// 2^20 Irwin-Hall draws (2,048 scenarios, 4 views, the 128 pixels of block 7 of each): the
// kernels' ih128 equal the reference's pixel_irwin_hall within kIrwinHallDrawAbs, and their
// sample's moments and KS distance from the normal are the exact distribution's
// (kIrwinHallDistribution) within sampling error.
TEST(Philox, IrwinHallKernelsFollowTheReferenceAndTheDistribution) {
  OpenCLRuntime rt;
  constexpr int kScenarios = 2048, kViews = 4;
  constexpr uint64_t kSeed = 0x9e3779b97f4a7c15ull, kFirst = 1000;
  const size_t groups = size_t(kScenarios) * kViews, n = groups * 128;
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(float));
  run(rt, R"(
kernel void ih_sample(ulong seed, ulong first, global float* out) {
  const size_t i = get_global_id(0);
  float16 g[8];
  ih128((uint2)((uint)seed, (uint)(seed >> 32)), first + i / 4, PS_STREAM_PIXEL_NOISE_FAST, (int)(i % 4), 7, g);
  for (int j = 0; j < 8; ++j) vstore16(g[j], 8 * i + j, out);
})",
      "ih_sample", groups, cl_ulong(kSeed), cl_ulong(kFirst), out);
  const std::vector<float> got = read<float>(rt, out, n);
  std::vector<double> kernel(got.begin(), got.end()), ref(n);
  double worst = 0;
  for (size_t k = 0; k < n; ++k) {
    const size_t i = k / 128;
    ref[k] = reference::pixel_irwin_hall(kSeed, kFirst + i / 4, int(i % 4), 7 * 128 + int(k % 128));
    worst = std::max(worst, std::abs(kernel[k] - ref[k]));
  }
  EXPECT_LE(worst, kIrwinHallDrawAbs) << "kernel against reference, largest difference";
  const DrawDistribution& e = kIrwinHallDistribution;
  const double dn = double(n);
  for (const auto* sample : {&kernel, &ref}) {
    SCOPED_TRACE(sample == &kernel ? "kernels" : "reference");
    const Distribution d = distribution(*sample);
    EXPECT_NEAR(d.mean, e.mean, 4 / std::sqrt(dn));
    EXPECT_NEAR(d.sd, e.sd, 4 / std::sqrt(2 * dn));
    EXPECT_NEAR(d.skewness, e.skewness, 4 * std::sqrt(6 / dn));
    EXPECT_NEAR(d.excess_kurtosis, e.excess_kurtosis, 4 * std::sqrt(24 / dn));
    EXPECT_LE(d.ks, e.ks_from_normal + d.ks_critical);
    EXPECT_LE(*std::max_element(sample->begin(), sample->end()), 3.365 + kIrwinHallDrawAbs);
  }
}

// What `portalsim tradeoff` samples for its noise columns (opencl::noise_draws) is each
// model's own draw, value by value: the physics MMW raw noise in its stream (table
// Gaussians, or Irwin-Hall under the fast tier) and the thesis pixel noise (Irwin-Hall in
// the fast tier). Draws of another stream would have the same distribution and pass any
// statistical check (mutation 46 of tools/mutations.txt).
TEST(Philox, TradeoffSamplesEachModelsOwnDraws) {
  OpenCLRuntime rt;
  constexpr uint64_t kSeed = 0x5eed5eed12345ull, kFirst = 77;
  constexpr size_t kScenarios = 16;
  constexpr int kCells = 1000;
  struct Case {
    const char* name;
    Model model;
    Tier tier;
    double (*ref)(uint64_t, uint64_t, int);
    double tolerance;
  };
  const Case cases[] = {
      {"physics, fast tier", Model::physics, Tier::fast,
       [](uint64_t s, uint64_t i, int p) { return reference::fast_gaussian(s, i, kStreamRawNoise, 0, p); },
       kIrwinHallDrawAbs},
      {"physics, standard tier", Model::physics, Tier::standard,
       [](uint64_t s, uint64_t i, int p) { return reference::table_gaussian(s, i, kStreamRawNoise, 0, p); },
       kTableGaussianAbs},
      {"thesis, fast tier", Model::thesis, Tier::fast,
       [](uint64_t s, uint64_t i, int p) { return reference::pixel_irwin_hall(s, i, 0, p); }, kIrwinHallDrawAbs},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::vector<double> got =
        opencl::noise_draws(rt, tier_fidelity(c.tier), opencl::KernelCounts::of(default_catalogue()), c.model, kSeed,
                            kFirst, kScenarios, kCells);
    ASSERT_EQ(got.size(), kScenarios * kCells);
    double worst = 0;
    for (size_t k = 0; k < got.size(); ++k)
      worst = std::max(worst, std::abs(got[k] - c.ref(kSeed, kFirst + k / kCells, int(k % kCells))));
    EXPECT_LE(worst, c.tolerance);
  }
}

TEST(Philox, DrawLayoutSeparatesEveryArgument) {
  const Philox4 a = draw(1, 2, 3, 4);
  EXPECT_NE(a, draw(2, 2, 3, 4));
  EXPECT_NE(a, draw(1, 3, 3, 4));
  EXPECT_NE(a, draw(1, 2, 4, 4));
  EXPECT_NE(a, draw(1, 2, 3, 5));
  EXPECT_NE(draw(0, 1ull << 32, 0, 0), draw(0, 0, 0, 0));  // the index's high word counts
  EXPECT_NE(draw(1ull << 32, 0, 0, 0), draw(0, 0, 0, 0));  // so does the seed's
}

TEST(Philox, BelowAndUniformStayInRange) {
  for (uint32_t r : {0u, 1u, 0x7fffffffu, 0xffffffffu}) {
    EXPECT_LT(below(r, 5), 5u);
    EXPECT_LT(uniform24(r), 1.0);
  }
  // The top 24 bits over 2^24: exact values at both ends and in between.
  EXPECT_EQ(uniform24(0xffu), 0.0);
  EXPECT_EQ(uniform24(0x100u), 1.0 / 16777216.0);
  EXPECT_EQ(uniform24(0x80000000u), 0.5);
  EXPECT_EQ(uniform24(0xffffffffu), 16777215.0 / 16777216.0);
  EXPECT_EQ(below(0xffffffffu, 5), 4u);
  EXPECT_EQ(below(0, 5), 0u);
}

TEST(Philox, KernelMatchesHost) {
  OpenCLRuntime rt;
  const size_t n = 512;
  std::vector<cl_ulong> seeds(n), index(n);
  std::vector<cl_uint> stream(n), element(n);
  for (size_t i = 0; i < n; ++i) {
    const Philox4 r = philox4x32_10({static_cast<uint32_t>(i), 99, 0, 0}, {7, 7});
    seeds[i] = i == 0 ? 0 : i == 1 ? ~0ull : (static_cast<uint64_t>(r[0]) << 32 | r[1]);
    index[i] = i == 2 ? ~0ull : (static_cast<uint64_t>(r[2]) << 20 | i);
    stream[i] = r[3] % 17;
    element[i] = r[0] ^ r[3];
  }
  cl::Buffer b_out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(cl_uint4));
  cl::Buffer b_gauss(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(cl_float2));
  run(rt, R"(
kernel void philox_test(global const ulong* seeds, global const ulong* index, global const uint* stream,
                        global const uint* element, global uint4* out, global float2* gauss) {
  const size_t i = get_global_id(0);
  const uint4 r = draw((uint2)((uint)seeds[i], (uint)(seeds[i] >> 32)), index[i], stream[i], element[i]);
  out[i] = r;
  float g0, g1;
  box_muller(r.x, r.y, &g0, &g1);
  gauss[i] = (float2)(g0, g1);
})",
      "philox_test", n, input(rt, seeds), input(rt, index), input(rt, stream), input(rt, element), b_out, b_gauss);
  const std::vector<cl_uint4> out = read<cl_uint4>(rt, b_out, n);
  const std::vector<cl_float2> gauss = read<cl_float2>(rt, b_gauss, n);
  for (size_t i = 0; i < n; ++i) {
    const Philox4 h = draw(seeds[i], index[i], stream[i], element[i]);
    for (int w = 0; w < 4; ++w) ASSERT_EQ(out[i].s[w], h[w]) << "draw " << i << " word " << w;
    // Box-Muller in float against double: the same uniforms, so close.
    const double u1 = 1.0 - uniform24(h[0]), u2 = uniform24(h[1]);
    const double rad = std::sqrt(-2.0 * std::log(u1));
    EXPECT_NEAR(gauss[i].s[0], rad * std::cos(6.283185307179586 * u2), 1e-4 * std::max(1.0, rad));
    EXPECT_NEAR(gauss[i].s[1], rad * std::sin(6.283185307179586 * u2), 1e-4 * std::max(1.0, rad));
  }
}

// The kernels' table Gaussians (backend/opencl/gauss_table.h): entry k is the normal
// quantile at (k + 1/2) / 4096 to 1e-12, odd about the middle, increasing, and the table's
// mean 0 and standard deviation within 2e-4 of 1; its extremes +-3.668.
TEST(Philox, GaussTableHoldsTheNormalQuantiles) {
  const std::vector<double>& t = gauss_table();
  ASSERT_EQ(t.size(), size_t(PS_GAUSS_TABLE));
  double sum = 0, sq = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double q = (k + 0.5) / PS_GAUSS_TABLE;
    EXPECT_NEAR(0.5 * std::erfc(-t[k] / std::sqrt(2.0)), q, 1e-12 * std::max(1.0, 1.0 / q)) << k;
    EXPECT_EQ(t[k], -t[t.size() - 1 - k]) << k;
    if (k > 0) {
      EXPECT_GT(t[k], t[k - 1]) << k;
    }
    sum += t[k];
    sq += t[k] * t[k];
  }
  EXPECT_NEAR(sum / t.size(), 0.0, 1e-12);
  const double sd = std::sqrt(sq / t.size());
  EXPECT_NEAR(sd, 1.0, 2e-4);
  EXPECT_NEAR(t[0], -3.668, 0.001);
}

// The table's bits set the physics noise's bytes in every tier, and they come from libm's
// erfc, log and exp (Newton's method; docs/model/determinism.md, "What the bytes depend
// on"): pinned here, so that a libm that moves any entry's last bit fails by name.
TEST(Philox, GaussTableBitsArePinned) {
  const std::vector<double>& t = gauss_table();
  EXPECT_EQ(XXH3_64bits(t.data(), t.size() * sizeof(double)), 0x9ffc23d1ccb5da73ull)
      << "the table Gaussians' bits moved: this libm's erfc, log or exp round differently";
}

}  // namespace portalsim
