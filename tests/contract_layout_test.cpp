// The host and the kernels lay out kernels/contract.h's launch records alike: the kernels,
// built at each parameter precision, write their sizes and offsets, and the host's compile
// of the same declarations must give them. The view's scalars (PsPhysMmw, PsPhysIr, their drawn ranges) are
// doubles on the host and floats or doubles in the kernels, converted one by one
// (backend/opencl/buffers.h, params): each field's index must agree, not its byte offset.
// The program is the runtime's (OpenCLRuntime::source), so tools/mutate.sh reaches it.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "backend/opencl/kernels.h"
#include "backend/opencl/runtime.h"
#include "contract.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim {
namespace {

// Each a byte offset or size of PsViewLaunch, then an index (offset over PS_PARAM) of the
// physics scalars, in one order on both sides.
#define PS_LAYOUT(OFFSET, SIZE, PARAM, SUBJECTS)                                                                  \
  SIZE(PsViewLaunch), OFFSET(PsViewLaunch, tables), OFFSET(PsViewLaunch, tables.display),                         \
      OFFSET(PsViewLaunch, tables.display.dyband), OFFSET(PsViewLaunch, frames), OFFSET(PsViewLaunch, rotate_lo), \
      OFFSET(PsViewLaunch, ranges_fp64), SIZE(PsPhysTables), PARAM(PsPhysMmw, common.window_min),                 \
      PARAM(PsPhysMmw, common.window_max), PARAM(PsPhysMmw, common.scene), PARAM(PsPhysMmw, common.clothing),     \
      PARAM(PsPhysMmw, common.drawn.lo), PARAM(PsPhysMmw, common.drawn.hi), PARAM(PsPhysMmw, netd),               \
      PARAM(PsPhysMmw, frames_as_one), PARAM(PsPhysIr, common.window_max), PARAM(PsPhysIr, common.clothing),      \
      PARAM(PsPhysIr, common.drawn.hi), SUBJECTS

#define HOST_OFFSET(T, F) (long)offsetof(T, F)
#define HOST_SIZE(T) (long)sizeof(T)
#define HOST_PARAM(T, F) (long)(offsetof(T, F) / sizeof(PS_PARAM))
#define HOST_SUBJECTS (long)PS_PHYS_SUBJECTS
const std::vector<long> kHost = {PS_LAYOUT(HOST_OFFSET, HOST_SIZE, HOST_PARAM, HOST_SUBJECTS)};

#define STR(...) #__VA_ARGS__
#define XSTR(...) STR(__VA_ARGS__)
const std::string kKernel = std::string(R"(
#define K_OFFSET(T, F) (long)__builtin_offsetof(T, F)
#define K_SIZE(T) (long)sizeof(T)
#define K_PARAM(T, F) (long)(__builtin_offsetof(T, F) / sizeof(PS_PARAM))
#define K_SUBJECTS (long)PS_PHYS_SUBJECTS
kernel void layout(global long* out) {
  const long v[] = {)") + XSTR(PS_LAYOUT(K_OFFSET, K_SIZE, K_PARAM, K_SUBJECTS)) +
                            R"(};
  for (int i = 0; i < (int)(sizeof v / sizeof v[0]); ++i) out[i] = v[i];
})";

std::vector<long> kernel_layout(OpenCLRuntime& rt, Precision precision) {
  Fidelity f;
  f.precision = precision;
  cl::Program prog(rt.context(), OpenCLRuntime::source() + kKernel);
  prog.build(("-cl-std=CL1.2 " + opencl::build_options(f, opencl::KernelCounts::of(default_catalogue()))).c_str());
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, kHost.size() * sizeof(cl_long));
  cl::Kernel k(prog, "layout");
  k.setArg(0, out);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1));
  std::vector<cl_long> got(kHost.size());
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, got.size() * sizeof(cl_long), got.data());
  return {got.begin(), got.end()};
}

}  // namespace

TEST(ContractLayout, KernelsAgreeWithHost) {
  OpenCLRuntime rt;
  for (Precision p : {Precision::fp32, Precision::fp64}) {
    SCOPED_TRACE(p == Precision::fp64 ? "fp64" : "fp32");
    const std::vector<long> got = kernel_layout(rt, p);
    for (size_t i = 0; i < kHost.size(); ++i) EXPECT_EQ(got[i], kHost[i]) << "entry " << i << " of PS_LAYOUT";
  }
}

}  // namespace portalsim
