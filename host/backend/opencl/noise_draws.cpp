#include "backend/opencl/noise_draws.h"

#include "backend/opencl/gauss_table.h"
#include "backend/opencl/kernels.h"

namespace portalsim::opencl {

std::vector<double> noise_draws(OpenCLRuntime& rt, const Fidelity& f, Model model, uint64_t seed, uint64_t first,
                                size_t scenarios, int cells) {
  Kernels K(rt, f);
  const size_t n = scenarios * static_cast<size_t>(cells);
  // The quantile table at the variant's parameter precision (double in fp64 builds).
  std::vector<double> table64(gauss_table().begin(), gauss_table().end());
  std::vector<float> table32(table64.begin(), table64.end());
  const size_t table_bytes = K.fp64() ? table64.size() * sizeof(double) : table32.size() * sizeof(float);
  void* table_data = K.fp64() ? static_cast<void*>(table64.data()) : static_cast<void*>(table32.data());
  cl::Buffer table(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, table_bytes, table_data);
  cl::Buffer out(rt.context(), CL_MEM_WRITE_ONLY, n * sizeof(float));
  cl::Kernel& k = K["noise_draws"];
  k.setArg(0, static_cast<cl_uint>(seed));
  k.setArg(1, static_cast<cl_uint>(seed >> 32));
  k.setArg(2, static_cast<cl_ulong>(first));
  k.setArg(3, static_cast<cl_int>(model == Model::physics));
  k.setArg(4, static_cast<cl_int>(f.draw == NoiseDraw::irwin_hall));
  k.setArg(5, static_cast<cl_int>(cells));
  k.setArg(6, table);
  k.setArg(7, out);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(scenarios));
  std::vector<float> got(n);
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, n * sizeof(float), got.data());
  return std::vector<double>(got.begin(), got.end());
}

}  // namespace portalsim::opencl
