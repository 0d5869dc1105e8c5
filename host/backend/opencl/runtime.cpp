#include "backend/opencl/runtime.h"

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

namespace portalsim {

namespace embedded {
extern const std::string_view kernel_program;
}

std::string OpenCLRuntime::source() { return std::string(embedded::kernel_program); }

namespace {
// Where PoCL keeps compiled kernels: POCL_CACHE_DIR, else $XDG_CACHE_HOME/pocl, else ~/.cache/pocl.
std::string pocl_cache() {
  if (const char* d = std::getenv("POCL_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/pocl";
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : "~") + "/.cache/pocl";
}
}  // namespace

OpenCLRuntime::OpenCLRuntime(const OpenCLOptions& options) {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    platforms.clear();  // no platform at all: said below
  }
  if (platforms.empty())
    throw std::runtime_error(
        "no OpenCL platform found (is pocl-opencl-icd installed?); --backend reference works without one");
  bool found = false;
  for (const cl::Platform& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;
    }
    for (const cl::Device& d : devices) {
      const std::string name = p.getInfo<CL_PLATFORM_NAME>() + " / " + d.getInfo<CL_DEVICE_NAME>();
      const bool wanted = options.device.empty() ? (d.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0
                                                 : name.find(options.device) != std::string::npos;
      if (wanted) {
        device_ = d;
        device_name_ = name;
        found = true;
        break;
      }
    }
    if (found) break;
  }
  if (!found)
    throw std::runtime_error(options.device.empty()
                                 ? "no OpenCL CPU device found (is pocl-opencl-icd installed? PoCL also offers none "
                                   "when its kernel cache, " +
                                       pocl_cache() + ", is not writable); --backend reference works without one"
                                 : "no OpenCL device matches \"" + options.device + "\"");
  if (options.compute_units > 0) {
    // Device fission: PoCL runs a sub-device's work on that many threads.
    const cl_uint max_units = device_.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
    if (options.compute_units < max_units) {
      const cl_device_partition_property props[] = {
          CL_DEVICE_PARTITION_EQUALLY, static_cast<cl_device_partition_property>(options.compute_units), 0};
      std::vector<cl::Device> subs;
      if (device_.createSubDevices(props, &subs) != CL_SUCCESS || subs.empty())
        throw std::runtime_error("cannot make a sub-device of " + std::to_string(options.compute_units) +
                                 " compute units on " + device_name_);
      device_ = subs[0];
      device_name_ += " (" + std::to_string(options.compute_units) + " of " + std::to_string(max_units) + " units)";
    }
  }
  context_ = cl::Context(device_);
  queue_ = cl::CommandQueue(context_, device_);
  program_ = cl::Program(context_, source());
  const auto t0 = std::chrono::steady_clock::now();
  try {
    program_.build({device_}, ("-cl-std=CL1.2 " + options.build_options).c_str());
  } catch (const cl::Error&) {
    throw std::runtime_error("OpenCL program build failed; PoCL compiles into its kernel cache, " + pocl_cache() +
                             ", which must be writable (or set POCL_CACHE_DIR):\n" +
                             program_.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_));
  }
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  variants_[""] = program_;
  base_options_ = options.build_options;
}

cl::Program& OpenCLRuntime::program(const std::string& options) {
  auto it = variants_.find(options);
  if (it != variants_.end()) return it->second;
  if (options.find("PRECISION_FP64") != std::string::npos &&
      device_.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") == std::string::npos)
    throw std::runtime_error("the exact tier needs fp64, and " + device_name_ + " has no cl_khr_fp64");
  cl::Program p(context_, source());
  try {
    p.build({device_}, ("-cl-std=CL1.2 " + base_options_ + " " + options).c_str());
  } catch (const cl::Error&) {
    throw std::runtime_error("OpenCL program build failed (" + options + "); PoCL's kernel cache, " + pocl_cache() +
                             ", must be writable (or set POCL_CACHE_DIR):\n" +
                             p.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_));
  }
  return variants_.emplace(options, p).first->second;
}

}  // namespace portalsim
