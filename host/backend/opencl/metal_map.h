// The physics metal detector's response to one object at many places (kernels/metal_physics.cl,
// metal_map): the bulk of a metal map (host/evaluate/metal_map.h). The reference's side is
// reference::metal_response.
#pragma once
#include <cstdint>
#include <vector>

#include "backend/opencl/runtime.h"
#include "scene/catalogue.h"

namespace portalsim::opencl {

// Each zone's coil record (kernels/contract.h, PS_MZ_*): transmit and receive coil, moments
// pointing into the portal, gain.
std::vector<double> metal_zone_records(const MetalPhysics& mp);

struct MetalResponses {
  std::vector<double> response;    // probes x zones: gain |H_R^T M H_T|, counts, unrounded
  std::vector<uint8_t> deduction;  // probes x zones: the response rounded half up, capped at 199
};

// `objects`: records of PS_MV_LEN doubles (tensor, long side x, z, y); `probes`: records of
// PS_MP_LEN doubles (centre x, y, z, object record). Throws EnvironmentError without fp64.
MetalResponses metal_responses(OpenCLRuntime& rt, const Catalogue& cat, const std::vector<double>& objects,
                               const std::vector<double>& probes);

}  // namespace portalsim::opencl
