// The built program of each fidelity variant (precision, fast math) and its kernels, made
// on first use (metal_physics needs cl_khr_fp64, so nothing is made before it is asked for).
#pragma once
#include <CL/opencl.hpp>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "backend/opencl/runtime.h"
#include "plan/plan.h"

namespace portalsim::opencl {

// The catalogue's counts a program is built for (-DPS_REGIONS, -DPS_ZONES): the strides of
// the kernels' object and zone rows and the bounds of their loops (kernels/contract.h).
struct KernelCounts {
  int regions = 0, zones = 0;
  static KernelCounts of(const Catalogue& cat) { return {cat.region_count(), cat.zones}; }
};

class Kernels {
 public:
  Kernels(OpenCLRuntime& rt, const Fidelity& f, KernelCounts counts);
  // The kernel called `name` in this variant's program.
  cl::Kernel& operator[](std::string_view name);
  bool fp64() const { return fp64_; }  // `param` and `real` are double
  size_t real_bytes() const { return fp64_ ? sizeof(cl_double) : sizeof(cl_float); }

 private:
  cl::Program program_;
  std::map<std::string, cl::Kernel, std::less<>> kernels_;
  bool fp64_ = false;
};

// One Kernels per variant, built once and kept.
class KernelVariants {
 public:
  KernelVariants(OpenCLRuntime& rt, KernelCounts counts) : rt_(rt), counts_(counts) {}
  Kernels& operator()(const Fidelity& f);

 private:
  OpenCLRuntime& rt_;
  KernelCounts counts_;
  std::map<std::string, std::unique_ptr<Kernels>> variants_;
};

// The program's build options for a variant: its precision's define, fast math, the counts.
std::string build_options(const Fidelity& f, KernelCounts counts);

}  // namespace portalsim::opencl
