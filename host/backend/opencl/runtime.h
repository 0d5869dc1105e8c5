// The OpenCL runtime: one device, context and queue, and the portalsim program built for
// each set of options.
#pragma once
#include <CL/opencl.hpp>
#include <map>
#include <string>
#include <vector>

#include "shared.h"

namespace portalsim {

struct OpenCLOptions {
  std::string device;          // substring of the platform or device name; empty = first CPU device
  std::string build_options;   // extra options for clBuildProgram
  unsigned compute_units = 0;  // > 0: a sub-device of this many compute units (threads on PoCL)
};

// What a device offers, as --list-devices prints it and `portalsim bench` plans by; a
// plain struct, so that code deciding by it can be tested with a device that is not here.
struct OpenCLDeviceInfo {
  std::string name;  // "platform / device": what --device matches a substring of
  std::string type;  // cpu, gpu, accelerator or other
  unsigned compute_units = 0;
  bool fp64 = false;  // cl_khr_fp64: the exact tier and --model physics's metal zones need it
};

// Every device of every OpenCL platform, in the order --device searches them; throws
// EnvironmentError (saying why: no platform, or PoCL's cache not writable) when there is none.
std::vector<OpenCLDeviceInfo> list_opencl_devices();

class OpenCLRuntime {
 public:
  explicit OpenCLRuntime(const OpenCLOptions& options = {});
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }
  // The program built with extra options (backend/opencl/kernels.h: build_options; the
  // catalogue's counts among them), built on first use and kept.
  cl::Program& program(const std::string& options);
  const std::string& device_name() const { return device_name_; }
  bool has_fp64() const;  // the device offers cl_khr_fp64
  OpenCLDeviceInfo info() const;
  double build_seconds() const { return build_seconds_; }  // every program built so far
  // kernels/shared.h and the kernels/ files, in CMakeLists.txt's order; or the file
  // PORTALSIM_KERNEL_PROGRAM names (tools/mutate.sh). Throws EnvironmentError where that
  // cannot be read.
  static std::string source();

 private:
  [[noreturn]] void build_failed(const cl::Program& p, const std::string& options) const;

  cl::Context context_;
  cl::Device device_;
  cl::CommandQueue queue_;
  std::map<std::string, cl::Program> variants_;
  std::string device_name_, base_options_;
  double build_seconds_ = 0;
};

// Rounds a work size up to the fixed local size: PoCL compiles a work-group function per
// local size, so every launch uses the same one.
constexpr size_t kLocalSize = PS_LOCAL_SIZE;
inline size_t padded(size_t n) { return (n + kLocalSize - 1) / kLocalSize * kLocalSize; }

}  // namespace portalsim
