#include "backend/opencl/metal_map.h"

#include <algorithm>

#include "backend/opencl/buffers.h"
#include "backend/opencl/kernels.h"
#include "backend/opencl/launch.h"
#include "base/error.h"

namespace portalsim::opencl {

std::vector<double> metal_zone_records(const MetalPhysics& mp) {
  std::vector<double> zones(mp.tx_side.size() * PS_MZ_LEN, 0.0);
  for (size_t z = 0; z < mp.tx_side.size(); ++z) {
    const double side = mp.tx_side[z];
    double* rec = &zones[z * PS_MZ_LEN];
    rec[PS_MZ_TX_X] = side * mp.panel_separation / 2.0;
    rec[PS_MZ_TX_Z] = mp.tx_height[z];
    rec[PS_MZ_TX_M] = -side * mp.tx_moment;
    rec[PS_MZ_RX_X] = -side * mp.panel_separation / 2.0;
    rec[PS_MZ_RX_Z] = mp.rx_height[z];
    rec[PS_MZ_RX_M] = side * mp.rx_moment;
    rec[PS_MZ_GAIN] = mp.gain[z];
  }
  return zones;
}

MetalResponses metal_responses(OpenCLRuntime& rt, const Catalogue& cat, const std::vector<double>& objects,
                               const std::vector<double>& probes) {
  const MetalPhysics& mp = cat.metal_physics;
  const size_t Z = static_cast<size_t>(cat.zones);
  if (!rt.has_fp64())
    throw EnvironmentError("metal maps compute the physics metal zones in fp64, and " + rt.device_name() +
                           " has no cl_khr_fp64; --backend reference works without it");
  Kernels K(rt, Fidelity{}, KernelCounts::of(cat));
  cl::Kernel& k = K["metal_map"];
  const size_t n = probes.size() / PS_MP_LEN;
  MetalResponses out;
  out.response.resize(n * Z);
  out.deduction.resize(n * Z);
  const cl::Buffer zone_rec = constant(rt.context(), metal_zone_records(mp)), records = constant(rt.context(), objects);
  // In chunks, so that the device's buffers stay bounded however large the map.
  constexpr size_t kChunk = 1 << 16;
  for (size_t first = 0; first < n; first += kChunk) {
    const size_t m = std::min(kChunk, n - first);
    const std::vector<double> part(probes.begin() + first * PS_MP_LEN, probes.begin() + (first + m) * PS_MP_LEN);
    cl::Buffer response(rt.context(), CL_MEM_WRITE_ONLY, m * Z * sizeof(double));
    cl::Buffer deduction(rt.context(), CL_MEM_WRITE_ONLY, m * Z);
    enqueue(rt.queue(), k, K.fp64(),
            MetalMapArgs{.zone_rec = zone_rec,
                         .objects = records,
                         .probes = constant(rt.context(), part),
                         .n = static_cast<cl_uint>(m),
                         .response = response,
                         .deduction = deduction},
            m);
    rt.queue().enqueueReadBuffer(response, CL_FALSE, 0, m * Z * sizeof(double), out.response.data() + first * Z);
    rt.queue().enqueueReadBuffer(deduction, CL_TRUE, 0, m * Z, out.deduction.data() + first * Z);
  }
  return out;
}

}  // namespace portalsim::opencl
