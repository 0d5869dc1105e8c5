#pragma once
#include "backend/backend.h"
#include "backend/opencl/runtime.h"

namespace portalsim {

// The kernels of kernels/ on an OpenCL device (PoCL on the CPU by default). The
// runtime is shared so that one built program serves many backends.
std::unique_ptr<Backend> make_opencl_backend(const Catalogue& cat, const AssetSet& assets,
                                             std::shared_ptr<OpenCLRuntime> runtime);

}  // namespace portalsim
