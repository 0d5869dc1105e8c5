// What `portalsim bench` can measure on a device. The fp64 reference is host code and runs
// anywhere; the exact tier computes in fp64 on the device, and generate --model physics
// computes the metal detector's coil fields in fp64, so a device without cl_khr_fp64
// runs neither. Decided from an OpenCLDeviceInfo alone, so that a test can describe a
// device that is not here.
#pragma once
#include <string>
#include <vector>

#include "backend/opencl/runtime.h"
#include "speed/paths.h"

namespace portalsim::speed {

enum class Measure { kernel, exact, loop, reference, end_to_end };
inline constexpr Measure kMeasures[] = {Measure::kernel, Measure::exact, Measure::loop, Measure::reference,
                                        Measure::end_to_end};
const char* measure_key(Measure m);    // "end_to_end": the JSON's name
const char* measure_title(Measure m);  // "end to end": the table's

// Why `m` of `path` does not run on `device`; empty when it runs.
std::string why_not(const SpeedPath& path, Measure m, const OpenCLDeviceInfo& device);

// For a device without fp64, what runs and what does not, in a few lines; empty when it
// has fp64.
std::string fp64_note(const std::vector<SpeedPath>& paths, const OpenCLDeviceInfo& device);

}  // namespace portalsim::speed
