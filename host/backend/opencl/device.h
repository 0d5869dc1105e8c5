// What every path of the OpenCL backend works with: the catalogue on the device, the
// derivations of each view's launch, the scratch buffers that grow with the batch, and the batch itself.
#pragma once
#include <CL/opencl.hpp>
#include <vector>

#include "assets/assets.h"
#include "backend/opencl/buffers.h"
#include "backend/opencl/device_catalogue.h"
#include "backend/opencl/runtime.h"
#include "backend/opencl/view_derive.h"
#include "scene/catalogue.h"

namespace portalsim::opencl {

struct Device {
  Device(const Catalogue& c, const AssetSet& a, OpenCLRuntime& r)
      : cat(c), assets(a), rt(r), data(c, a, r.context()), derived(c, a, r.context()), pooled_only(c.sensors.size()) {}
  cl::Context& ctx() { return rt.context(); }
  cl::CommandQueue& queue() { return rt.queue(); }

  const Catalogue& cat;
  const AssetSet& assets;
  OpenCLRuntime& rt;
  DeviceCatalogue data;
  ViewDerivations derived;  // what each (plan, view) launch reads
  // A view launch's placement records, field between stages, MMW raw grid and per-scenario
  // scratch (kernels/composite.cl, VIEW_STAGE_ARGS).
  Grown records, field, raw, view_scratch;
  std::vector<Grown> pooled_only;  // per view: its images where they are only pooled
};

// One batch on the device: its scenarios' subjects and objects, the run's seed and the
// batch's first scenario index, or where the batch is not contiguous (SceneBatch::indices)
// each scenario's index (null otherwise: kernels/lib/philox.cl, scenario_index).
struct DeviceBatch {
  size_t n = 0;
  cl::Buffer subject, objects;
  cl_uint2 seed{}, first{};
  cl::Buffer indices;
  std::vector<char> variants;  // by variant id: carried by a scenario of the batch (PathTables)
};

}  // namespace portalsim::opencl
