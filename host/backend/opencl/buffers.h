// Device buffers as the backend's paths make them: grown scratch, read-only constants,
// views of host memory.
#pragma once
#include <CL/opencl.hpp>
#include <algorithm>
#include <cstring>
#include <vector>

#include "backend/opencl/runtime.h"

namespace portalsim::opencl {

// A 64-bit number as the kernels' uint2: low word first.
inline cl_uint2 split(uint64_t v) {
  cl_uint2 r;
  r.s[0] = static_cast<cl_uint>(v);
  r.s[1] = static_cast<cl_uint>(v >> 32);
  return r;
}

// A device buffer that grows to the largest batch seen and is then reused.
struct Grown {
  cl::Buffer buf;
  size_t bytes = 0;
  cl::Buffer& at_least(cl::Context& ctx, size_t want) {
    if (want > bytes || bytes == 0) {
      bytes = std::max<size_t>(want, 1);
      buf = cl::Buffer(ctx, CL_MEM_READ_WRITE, bytes);
    }
    return buf;
  }
};

// A read-only copy of `v` (one element where empty: OpenCL has no empty buffer).
template <class T>
cl::Buffer constant(cl::Context& ctx, const std::vector<T>& v) {
  std::vector<T> copy = v;
  if (copy.empty()) copy.resize(1);
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, copy.size() * sizeof(T), copy.data());
}

// Model parameters at the kernels' parameter precision (kernels/lib/precision.cl).
inline cl::Buffer params(cl::Context& ctx, bool fp64, const std::vector<double>& v) {
  return fp64 ? constant(ctx, v) : constant(ctx, std::vector<cl_float>(v.begin(), v.end()));
}

// A device view of host memory: PoCL on the CPU writes there directly.
template <class T>
cl::Buffer wrap(cl::Context& ctx, std::vector<T>& v) {
  return cl::Buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, v.size() * sizeof(T), v.data());
}

// Makes the kernels' writes visible in host memory (a no-op copy where shared).
template <class T>
void sync(cl::CommandQueue& q, cl::Buffer& b, std::vector<T>& v) {
  const size_t bytes = v.size() * sizeof(T);
  void* p = q.enqueueMapBuffer(b, CL_TRUE, CL_MAP_READ, 0, bytes);
  if (p != v.data()) std::memcpy(v.data(), p, bytes);
  q.enqueueUnmapMemObject(b, p);
}

}  // namespace portalsim::opencl
