// Typed kernel arguments: one struct per kernel signature, its fields in the kernel's
// order, written once (an X-macro list) so that the fields and the setArg run cannot
// disagree. Call sites name each field (designated initialisers: a wrong name or order is
// a compile error, a missing field a -Wmissing-field-initializers warning), and set()
// checks the count against the kernel's own.
#pragma once
#include <CL/opencl.hpp>
#include <stdexcept>
#include <string>

#include "backend/opencl/runtime.h"
#include "shared.h"

namespace portalsim::opencl {

// A model parameter at the kernels' parameter precision (kernels/lib/precision.cl: `param`),
// double in fp64 builds, float otherwise.
struct Real {
  double value = 0;
};

namespace arg {
inline void set(cl::Kernel& k, cl_uint i, bool fp64, const Real& r) {
  if (fp64)
    k.setArg(i, static_cast<cl_double>(r.value));
  else
    k.setArg(i, static_cast<cl_float>(r.value));
}
inline void set(cl::Kernel& k, cl_uint i, bool, const PsViewLaunch& L) { k.setArg(i, sizeof L, &L); }
template <class T>
void set(cl::Kernel& k, cl_uint i, bool, const T& v) {
  k.setArg(i, v);
}
// Throws std::logic_error when the kernel takes another number of arguments than `given`.
inline void check_count(cl::Kernel& k, cl_uint given) {
  const cl_uint want = k.getInfo<CL_KERNEL_NUM_ARGS>();
  if (want != given)
    throw std::logic_error("kernel " + k.getInfo<CL_KERNEL_FUNCTION_NAME>() + " takes " + std::to_string(want) +
                           " arguments, its launch struct has " + std::to_string(given));
}
}  // namespace arg

#define PS_ARG_FIELD(type, name) type name;
#define PS_ARG_COUNT(type, name) +1
#define PS_ARG_SET(type, name) arg::set(k, i++, fp64, name);
// struct NAME with the fields of LIST (X(type, name) ...) and set(kernel, fp64), which
// checks the count before it sets anything.
#define PS_KERNEL_ARGS(NAME, LIST)               \
  struct NAME {                                  \
    LIST(PS_ARG_FIELD)                           \
    void set(cl::Kernel& k, bool fp64) const {   \
      arg::check_count(k, 0 LIST(PS_ARG_COUNT)); \
      cl_uint i = 0;                             \
      LIST(PS_ARG_SET)                           \
    }                                            \
  };

// clang-format off
// VIEW_STAGE_ARGS (kernels/composite.cl): place_view, render_view, every stage kernel and
// the view fast paths' kernels.
#define PS_VIEW_STAGE_ARGS(X)  \
  X(cl::Buffer, atlas)         \
  X(cl::Buffer, bases)         \
  X(cl::Buffer, sprites)       \
  X(cl::Buffer, places)        \
  X(cl::Buffer, noise_offsets) \
  X(cl::Buffer, noise_gains)   \
  X(cl::Buffer, subject)       \
  X(cl::Buffer, objects)       \
  X(PsViewLaunch, L)           \
  X(Real, alpha)               \
  X(cl::Buffer, records)       \
  X(cl::Buffer, field)         \
  X(cl::Buffer, out)           \
  X(cl::Buffer, phys)          \
  X(cl::Buffer, raw)           \
  X(cl::Buffer, scratch)       \
  X(cl::Buffer, indices)
PS_KERNEL_ARGS(ViewStageArgs, PS_VIEW_STAGE_ARGS)

// kernels/pool.cl
#define PS_POOL_BLOCKS_ARGS(X) \
  X(cl::Buffer, img)           \
  X(cl_uint, n)                \
  X(cl_int, width)             \
  X(cl_int, height)            \
  X(cl_int, block)             \
  X(cl_int, blocks_x)          \
  X(cl_int, blocks_y)          \
  X(cl_int, offset)            \
  X(cl_int, row_len)           \
  X(cl::Buffer, features)
PS_KERNEL_ARGS(PoolBlocksArgs, PS_POOL_BLOCKS_ARGS)

#define PS_POOL_REGIONS_ARGS(X) \
  X(cl::Buffer, img)            \
  X(cl_uint, n)                 \
  X(cl_int, width)              \
  X(cl_int, height)             \
  X(cl::Buffer, rects)          \
  X(cl_uint, region_mask)       \
  X(cl_int, offset)             \
  X(cl_int, row_len)            \
  X(cl::Buffer, features)
PS_KERNEL_ARGS(PoolRegionsArgs, PS_POOL_REGIONS_ARGS)

// kernels/metal.cl
#define PS_METAL_ZONES_ARGS(X)    \
  X(cl::Buffer, influence)        \
  X(cl::Buffer, variant_category) \
  X(cl::Buffer, base_zones)       \
  X(cl::Buffer, subject)          \
  X(cl::Buffer, objects)          \
  X(cl_uint, n)                   \
  X(cl_uint2, seed)               \
  X(cl_uint2, first)              \
  X(cl::Buffer, indices)          \
  X(cl::Buffer, drawn)            \
  X(cl::Buffer, out)
PS_KERNEL_ARGS(MetalZonesArgs, PS_METAL_ZONES_ARGS)

// kernels/metal_physics.cl
#define PS_METAL_PHYSICS_ARGS(X) \
  X(cl::Buffer, zone_rec)        \
  X(cl::Buffer, region_rec)      \
  X(cl::Buffer, tensors)         \
  X(cl::Buffer, base_zones)      \
  X(cl::Buffer, subject)         \
  X(cl::Buffer, objects)         \
  X(cl_uint, n)                  \
  X(cl_uint2, seed)              \
  X(cl_uint2, first)             \
  X(cl::Buffer, indices)         \
  X(cl::Buffer, drawn)           \
  X(cl_double, jitter)           \
  X(cl_double, half_width)       \
  X(cl_double, scale)            \
  X(cl_double, body_height)      \
  X(cl::Buffer, out)
PS_KERNEL_ARGS(MetalPhysicsArgs, PS_METAL_PHYSICS_ARGS)

#define PS_METAL_MAP_ARGS(X) \
  X(cl::Buffer, zone_rec)    \
  X(cl::Buffer, objects)     \
  X(cl::Buffer, probes)      \
  X(cl_uint, n)              \
  X(cl::Buffer, response)    \
  X(cl::Buffer, deduction)
PS_KERNEL_ARGS(MetalMapArgs, PS_METAL_MAP_ARGS)

// kernels/pool_sparse.cl
#define PS_BASE_FEATURES_ARGS(X) \
  X(cl::Buffer, atlas)           \
  X(cl::Buffer, bases)           \
  X(cl::Buffer, rects)           \
  X(cl::Buffer, pooled)          \
  X(cl_int, npooled)             \
  X(cl_int, views)               \
  X(cl::Buffer, region_slot)     \
  X(cl_int, subjects)            \
  X(cl_int, width)               \
  X(cl_int, height)              \
  X(cl_int, block)               \
  X(cl_int, blocks_x)            \
  X(cl_int, blocks_y)            \
  X(cl_int, row_len)             \
  X(cl::Buffer, sums)            \
  X(cl::Buffer, means)
PS_KERNEL_ARGS(BaseFeaturesArgs, PS_BASE_FEATURES_ARGS)

#define PS_FOOTPRINT_DELTAS_ARGS(X) \
  X(cl::Buffer, atlas)              \
  X(cl::Buffer, bases)              \
  X(cl::Buffer, fps)                \
  X(cl::Buffer, noise_offsets)      \
  X(cl::Buffer, noise_gains)        \
  X(cl::Buffer, rects)              \
  X(cl::Buffer, pooled)             \
  X(cl_int, views)                  \
  X(cl::Buffer, region_slot)        \
  X(cl_int, combos)                 \
  X(cl_int, subjects)               \
  X(cl_int, patterns)               \
  X(cl_int, width)                  \
  X(cl_int, block)                  \
  X(Real, alpha)                    \
  X(cl_int, tile)                   \
  X(cl_int, use_noise)              \
  X(cl::Buffer, deltas)             \
  X(cl::Buffer, region_deltas)
PS_KERNEL_ARGS(FootprintDeltasArgs, PS_FOOTPRINT_DELTAS_ARGS)

#define PS_SPARSE_PATTERNS_ARGS(X) \
  X(cl_uint, n)                    \
  X(cl_int, patterns)              \
  X(cl_uint2, seed)                \
  X(cl_uint2, first)               \
  X(cl::Buffer, indices)           \
  X(cl::Buffer, out)
PS_KERNEL_ARGS(SparsePatternsArgs, PS_SPARSE_PATTERNS_ARGS)

#define PS_FEATURES_SPARSE_ARGS(X) \
  X(cl::Buffer, atlas)             \
  X(cl::Buffer, bases)             \
  X(cl::Buffer, fps)               \
  X(cl::Buffer, deltas)            \
  X(cl::Buffer, region_deltas)     \
  X(cl::Buffer, base_sums)         \
  X(cl::Buffer, base_means)        \
  X(cl::Buffer, noise_offsets)     \
  X(cl::Buffer, noise_gains)       \
  X(cl::Buffer, rects)             \
  X(cl::Buffer, pooled)            \
  X(cl_int, npooled)               \
  X(cl_int, views)                 \
  X(cl::Buffer, region_slot)       \
  X(cl::Buffer, subject)           \
  X(cl::Buffer, objects)           \
  X(cl::Buffer, patterns)          \
  X(cl_uint, n)                    \
  X(cl_int, subjects)              \
  X(cl_int, pattern_count)         \
  X(cl_int, width)                 \
  X(cl_int, height)                \
  X(cl_int, block)                 \
  X(cl_int, blocks_x)              \
  X(cl_int, blocks_y)              \
  X(Real, alpha)                   \
  X(cl_int, tile)                  \
  X(cl_int, use_noise)             \
  X(cl_int, row_len)               \
  X(cl::Buffer, features)
PS_KERNEL_ARGS(FeaturesSparseArgs, PS_FEATURES_SPARSE_ARGS)

#define PS_ANALYTIC_NOISE_ARGS(X) \
  X(cl::Buffer, features)         \
  X(cl::Buffer, rects)            \
  X(cl::Buffer, grids)            \
  X(cl_uint, n)                   \
  X(cl_int, block)                \
  X(cl_int, npooled)              \
  X(cl_int, row_len)              \
  X(cl::Buffer, drawn)            \
  X(cl_uint2, seed)               \
  X(cl_uint2, first)              \
  X(cl::Buffer, indices)
PS_KERNEL_ARGS(AnalyticNoiseArgs, PS_ANALYTIC_NOISE_ARGS)

// kernels/physics_features.cl
#define PS_PHYSICS_FEATURES_ARGS(X) \
  X(cl::Buffer, raw)                \
  X(cl::Buffer, first)              \
  X(cl::Buffer, cells)              \
  X(cl::Buffer, weights)            \
  X(cl::Buffer, columns)            \
  X(cl_int, count)                  \
  X(cl_int, raw_cells)              \
  X(cl::Buffer, phys)               \
  X(cl_int, row_len)                \
  X(cl::Buffer, features)           \
  X(PsViewLaunch, L)                \
  X(cl::Buffer, records)            \
  X(cl::Buffer, subject)            \
  X(cl::Buffer, objects)            \
  X(cl::Buffer, base_features)      \
  X(cl::Buffer, object_range)       \
  X(cl::Buffer, pair_index)         \
  X(cl::Buffer, object_feature)     \
  X(cl::Buffer, object_value)       \
  X(Real, netd_lo)                  \
  X(Real, netd_hi)                  \
  X(cl_int2, frames)                \
  X(cl_int8, dims)                  \
  X(cl::Buffer, noise)              \
  X(cl::Buffer, scratch)            \
  X(cl::Buffer, indices)
PS_KERNEL_ARGS(PhysicsFeaturesArgs, PS_PHYSICS_FEATURES_ARGS)

// kernels/noise_draws.cl (portalsim tradeoff's noise samples)
#define PS_NOISE_DRAWS_ARGS(X) \
  X(cl_uint, seed_lo)          \
  X(cl_uint, seed_hi)          \
  X(cl_ulong, first)           \
  X(cl_int, physics)           \
  X(cl_int, cells)             \
  X(cl::Buffer, table)         \
  X(cl::Buffer, out)
PS_KERNEL_ARGS(NoiseDrawsArgs, PS_NOISE_DRAWS_ARGS)
// clang-format on

#undef PS_KERNEL_ARGS
#undef PS_ARG_SET
#undef PS_ARG_COUNT
#undef PS_ARG_FIELD

// Sets `args` on `k` and queues it over `items` work-items (padded to the fixed local
// size), from `offset`.
template <class Args>
void enqueue(cl::CommandQueue& q, cl::Kernel& k, bool fp64, const Args& args, size_t items, size_t offset = 0) {
  args.set(k, fp64);
  q.enqueueNDRangeKernel(k, offset ? cl::NDRange(offset) : cl::NullRange, cl::NDRange(padded(items)),
                         cl::NDRange(kLocalSize));
}

}  // namespace portalsim::opencl
