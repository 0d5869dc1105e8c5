// The counter generator: published known-answer vectors, and the kernel copy
// (kernels/philox.cl) bit-identical to the host copy (scene/philox.h).
#include "scene/philox.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include "backend/opencl/gauss_table.h"
#include "backend/opencl/runtime.h"

namespace portalsim {
namespace embedded {
extern const std::string_view kernel_program;
}

TEST(Philox, KnownAnswerVectors) {
  // Random123 kat_vectors, philox4x32_10.
  EXPECT_EQ(philox4x32_10({0, 0, 0, 0}, {0, 0}), (Philox4{0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u}));
  EXPECT_EQ(philox4x32_10({0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu}, {0xffffffffu, 0xffffffffu}),
            (Philox4{0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu}));
  EXPECT_EQ(philox4x32_10({0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u}, {0xa4093822u, 0x299f31d0u}),
            (Philox4{0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u}));
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
  const std::string src = std::string(embedded::kernel_program) + R"(
kernel void philox_test(global const ulong* seeds, global const ulong* index, global const uint* stream,
                        global const uint* element, global uint4* out, global float2* gauss) {
  const size_t i = get_global_id(0);
  const uint4 r = draw((uint2)((uint)seeds[i], (uint)(seeds[i] >> 32)), index[i], stream[i], element[i]);
  out[i] = r;
  gauss[i] = gauss2(r.x, r.y);
})";
  cl::Program prog(rt.context(), src);
  prog.build("-cl-std=CL1.2");
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
  auto in = [&](auto& v) {
    return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(v[0]), v.data());
  };
  cl::Buffer b_seed = in(seeds), b_index = in(index), b_stream = in(stream), b_element = in(element);
  cl::Buffer b_out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(cl_uint4));
  cl::Buffer b_gauss(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(cl_float2));
  cl::Kernel k(prog, "philox_test");
  k.setArg(0, b_seed);
  k.setArg(1, b_index);
  k.setArg(2, b_stream);
  k.setArg(3, b_element);
  k.setArg(4, b_out);
  k.setArg(5, b_gauss);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n), cl::NDRange(kLocalSize));
  std::vector<cl_uint4> out(n);
  std::vector<cl_float2> gauss(n);
  rt.queue().enqueueReadBuffer(b_out, CL_TRUE, 0, n * sizeof(cl_uint4), out.data());
  rt.queue().enqueueReadBuffer(b_gauss, CL_TRUE, 0, n * sizeof(cl_float2), gauss.data());
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

}  // namespace portalsim
