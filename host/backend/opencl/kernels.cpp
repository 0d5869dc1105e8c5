#include "backend/opencl/kernels.h"

namespace portalsim::opencl {

std::string build_options(const Fidelity& f, KernelCounts counts) {
  std::string o = f.precision == Precision::fp64      ? "-DPRECISION_FP64"
                  : f.precision == Precision::fixed16 ? "-DPRECISION_FIXED"
                                                      : "";
  if (f.fast_math) o += " -cl-fast-relaxed-math";
  if (f.draw == NoiseDraw::irwin_hall) o += " -DNOISE_DRAW_IH";
  return o + " -DPS_REGIONS=" + std::to_string(counts.regions) + " -DPS_ZONES=" + std::to_string(counts.zones);
}

Kernels::Kernels(OpenCLRuntime& rt, const Fidelity& f, KernelCounts counts)
    : program_(rt.program(build_options(f, counts))), fp64_(f.precision == Precision::fp64) {}

cl::Kernel& Kernels::operator[](std::string_view name) {
  auto it = kernels_.find(name);
  if (it == kernels_.end()) {
    const std::string kernel(name);
    it = kernels_.emplace(kernel, cl::Kernel(program_, kernel.c_str())).first;
  }
  return it->second;
}

Kernels& KernelVariants::operator()(const Fidelity& f) {
  std::unique_ptr<Kernels>& k = variants_[build_options(f, counts_)];
  if (!k) k = std::make_unique<Kernels>(rt_, f, counts_);
  return *k;
}

}  // namespace portalsim::opencl
