#include "backend/opencl/runtime.h"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "backend/opencl/drivers.h"
#include "base/embedded.h"
#include "base/error.h"

namespace portalsim {

namespace fs = std::filesystem;

// PORTALSIM_KERNEL_PROGRAM names a file that replaces the built-in program as a whole:
// tools/mutate.sh runs the suites on mutated kernels this way, without a relink.
std::string OpenCLRuntime::source() {
  const char* file = std::getenv("PORTALSIM_KERNEL_PROGRAM");
  if (!file || !*file) return std::string(embedded::kernel_program);
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().empty())
    throw EnvironmentError(std::string("PORTALSIM_KERNEL_PROGRAM=") + file +
                           ": cannot read a kernel program there; unset it to use the built-in kernels");
  return text.str();
}

namespace {
// Where PoCL keeps compiled kernels: POCL_CACHE_DIR, else $XDG_CACHE_HOME/pocl, else ~/.cache/pocl.
std::string pocl_cache() {
  if (const char* d = std::getenv("POCL_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/pocl";
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : "~") + "/.cache/pocl";
}

// What keeps PoCL from writing its kernel cache, or "" where nothing does: the cache, or
// the nearest of its parents that exists, must be a writable folder.
std::string cache_problem() {
  std::error_code ec;
  fs::path dir = pocl_cache();
  while (!dir.empty() && !fs::exists(dir, ec) && dir != dir.parent_path()) dir = dir.parent_path();
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    return "must be a writable folder, and " + (dir == pocl_cache() ? std::string("it") : dir.string()) + " is a file";
  if (::access(dir.c_str(), W_OK) != 0)
    return dir == pocl_cache()
               ? "must be writable, and is not (" + std::string(std::strerror(errno)) + ")"
               : "is missing and cannot be made: " + dir.string() + " is not writable (" + std::strerror(errno) + ")";
  return "";
}

OpenCLDeviceInfo describe(const std::string& name, const cl::Device& d) {
  OpenCLDeviceInfo info;
  info.name = name;
  const cl_device_type t = d.getInfo<CL_DEVICE_TYPE>();
  info.type = (t & CL_DEVICE_TYPE_CPU)           ? "cpu"
              : (t & CL_DEVICE_TYPE_GPU)         ? "gpu"
              : (t & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
                                                 : "other";
  info.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
  info.fp64 = d.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
  return info;
}

// Every device of every platform with its "platform / device" name, in platform order.
// `failed` gets the OpenCL call that failed on the way ("" where none did).
std::vector<std::pair<std::string, cl::Device>> all_devices(std::string& failed) {
  failed.clear();
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    platforms.clear();  // no platform at all: the caller says so
    failed = std::string(e.what()) + " returned " + std::to_string(e.err());
  }
  std::vector<std::pair<std::string, cl::Device>> all;
  for (const cl::Platform& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error& e) {
      failed = p.getInfo<CL_PLATFORM_NAME>() + ": " + e.what() + " returned " + std::to_string(e.err());
      continue;
    }
    for (const cl::Device& d : devices)
      all.emplace_back(p.getInfo<CL_PLATFORM_NAME>() + " / " + d.getInfo<CL_DEVICE_NAME>(), d);
  }
  return all;
}

// Why OpenCL is not usable, after `what` ("no OpenCL platform found") and `call` (the OpenCL
// call that failed and its error, or ""): first what the drivers' search found (drivers.h),
// where no driver is installed or one does not load; else PoCL's kernel cache, without which
// PoCL offers no platform, no device or no program.
std::string not_usable(const std::string& what, const std::string& call) {
  const std::string failed = what + (call.empty() ? "" : ": " + call);
  const DriverSearch drivers = search_opencl_drivers();
  if (!drivers.all_load) return failed + "; " + drivers.text + "; --backend reference works without OpenCL";
  if (const std::string problem = cache_problem(); !problem.empty())
    return "PoCL's kernel cache, " + pocl_cache() + ", " + problem + " (" + failed +
           "); POCL_CACHE_DIR, or XDG_CACHE_HOME, must name a writable folder; --backend reference works without "
           "OpenCL";
  return failed + " (" + drivers.text + "); --backend reference works without OpenCL";
}
}  // namespace

std::vector<OpenCLDeviceInfo> list_opencl_devices() {
  std::string failed;
  std::vector<OpenCLDeviceInfo> list;
  for (const auto& [name, d] : all_devices(failed)) list.push_back(describe(name, d));
  if (list.empty()) throw EnvironmentError(not_usable("no OpenCL platform found", failed));
  return list;
}

OpenCLRuntime::OpenCLRuntime(const OpenCLOptions& options) {
  std::string failed;
  const auto devices = all_devices(failed);
  if (devices.empty()) throw EnvironmentError(not_usable("no OpenCL platform found", failed));
  bool found = false;
  for (const auto& [name, d] : devices) {
    const bool wanted = options.device.empty() ? (d.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0
                                               : name.find(options.device) != std::string::npos;
    if (wanted) {
      device_ = d;
      device_name_ = name;
      found = true;
      break;
    }
  }
  if (!found && !options.device.empty()) {
    std::string names;
    for (const auto& [name, d] : devices) names += (names.empty() ? "" : "; ") + name;
    throw InputError("--device: no OpenCL device matches \"" + options.device + "\"; the devices are: " + names +
                     " (portalsim bench --list-devices)");
  }
  if (!found) throw EnvironmentError(not_usable("no OpenCL CPU device found", failed));
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
  base_options_ = options.build_options;
}

// PoCL compiles into its kernel cache: a cache it cannot write is the machine's problem
// (exit 5), anything else a bug in the kernels (internal).
void OpenCLRuntime::build_failed(const cl::Program& p, const std::string& options) const {
  const std::string log = p.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
  const std::string what = "OpenCL program build failed" + (options.empty() ? "" : " (" + options + ")");
  if (!cache_problem().empty()) throw EnvironmentError(not_usable(what, "") + "\n" + log);
  throw std::runtime_error(what + ":\n" + log);
}

bool OpenCLRuntime::has_fp64() const {
  return device_.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
}

OpenCLDeviceInfo OpenCLRuntime::info() const { return describe(device_name_, device_); }

cl::Program& OpenCLRuntime::program(const std::string& options) {
  auto it = variants_.find(options);
  if (it != variants_.end()) return it->second;
  if (options.find("PRECISION_FP64") != std::string::npos && !has_fp64())
    throw EnvironmentError("the exact tier needs fp64, and " + device_name_ + " has no cl_khr_fp64");
  cl::Program p(context_, source());
  const auto t0 = std::chrono::steady_clock::now();
  try {
    p.build({device_}, ("-cl-std=CL1.2 " + base_options_ + " " + options).c_str());
  } catch (const cl::Error&) {
    build_failed(p, options);
  }
  build_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return variants_.emplace(options, p).first->second;
}

}  // namespace portalsim
