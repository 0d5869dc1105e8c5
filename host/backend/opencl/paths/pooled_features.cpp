// The features of plans that no features path takes: each pooled view rendered by its view
// path, then its block and region means (kernels/pool.cl); and the block-mean noise model,
// which every features path's means get where it is chosen (kernels/pool_sparse.cl).
#include "backend/opencl/buffers.h"
#include "backend/opencl/launch.h"
#include "backend/opencl/paths/paths.h"
#include "backend/opencl/physics_params.h"

namespace portalsim::opencl {

void pool_view(Device& d, Kernels& K, const FeatureLayout& lay, const DeviceBatch& b, int slot, const cl::Buffer& img,
               const cl::Buffer& features) {
  const int view = lay.pooled[slot];
  const Sensor& s = d.cat.sensors[view];
  const cl_uint n = static_cast<cl_uint>(b.n);
  const int row_len = lay.image_features();
  // Each region's mean is the first pooled view's that sees it (region_slot).
  uint32_t regions = 0;
  for (int r = 0; r < lay.regions; ++r)
    if (region_slot(d.cat, lay, r) == slot) regions |= s.region_mask & (1u << r);
  enqueue(d.queue(), K["pool_blocks"], K.fp64(),
          PoolBlocksArgs{.img = img,
                         .n = n,
                         .width = s.width,
                         .height = s.height,
                         .block = lay.block,
                         .blocks_x = lay.grids[slot].blocks_x,
                         .blocks_y = lay.grids[slot].blocks_y,
                         .offset = lay.grids[slot].offset,
                         .row_len = row_len,
                         .features = features},
          b.n * lay.grids[slot].blocks());
  enqueue(d.queue(), K["pool_regions"], K.fp64(),
          PoolRegionsArgs{.img = img,
                          .n = n,
                          .width = s.width,
                          .height = s.height,
                          .rects = d.data.view_rects[view],
                          .region_mask = regions,
                          .offset = lay.block_features(),
                          .row_len = row_len,
                          .features = features},
          b.n * lay.regions);
}

void block_mean_noise(Device& d, Kernels& K, const Plan& plan, const DeviceBatch& b, const cl::Buffer& features) {
  const FeatureLayout lay = FeatureLayout::of(d.cat, plan.model.block);
  std::vector<cl_int4> grids;
  for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
    const Sensor& s = d.cat.sensors[lay.pooled[slot]];
    grids.push_back({{s.width, s.height, lay.grids[slot].blocks_x, lay.grids[slot].offset}});
  }
  enqueue(d.queue(), K["analytic_noise"], K.fp64(),
          AnalyticNoiseArgs{.features = features,
                            .rects = d.data.region_rects,
                            .grids = constant(d.ctx(), grids),
                            .n = static_cast<cl_uint>(b.n),
                            .block = lay.block,
                            .npooled = static_cast<cl_int>(lay.pooled.size()),
                            .row_len = lay.image_features(),
                            .drawn = params(d.ctx(), K.fp64(), drawn_params(plan.model)),
                            .seed = b.seed,
                            .first = b.first,
                            .indices = b.indices},
          b.n);
}

}  // namespace portalsim::opencl
