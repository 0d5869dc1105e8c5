#include "backend/opencl/noise_draws.h"

#include "backend/opencl/buffers.h"
#include "backend/opencl/gauss_table.h"
#include "backend/opencl/kernels.h"
#include "backend/opencl/launch.h"

namespace portalsim::opencl {

std::vector<double> noise_draws(OpenCLRuntime& rt, const Fidelity& f, KernelCounts counts, Model model, uint64_t seed,
                                uint64_t first, size_t scenarios, int cells) {
  Kernels K(rt, f, counts);
  const size_t n = scenarios * static_cast<size_t>(cells);
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(float));
  cl::Kernel& k = K["noise_draws"];
  // Kept to the end: a kernel argument does not hold its buffer.
  const NoiseDrawsArgs args{
      .seed_lo = static_cast<cl_uint>(seed),
      .seed_hi = static_cast<cl_uint>(seed >> 32),
      .first = first,
      .physics = model == Model::physics,
      .cells = cells,
      .table = params(rt.context(), K.fp64(), gauss_table()),  // the variant's parameter precision
      .out = out};
  args.set(k, K.fp64());
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(scenarios));
  std::vector<float> got(n);
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, n * sizeof(float), got.data());
  return std::vector<double>(got.begin(), got.end());
}

}  // namespace portalsim::opencl
