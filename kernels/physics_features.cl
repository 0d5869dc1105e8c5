// Features-only runs of the physics model from the MMW raw grid that physics_raw wrote
// (host/backend/opencl/raw_grid_pooling.h): each feature of the pooled view is its
// tabulated weighted sum of raw cells in kelvin through the display window, clamped to
// 0..255: the mean of its unrounded, unclamped pixels. One work-item per scenario.
kernel void physics_features(global const preal* raw, global const int* first, global const int* cells,
                             global const param* weights, global const int* columns, int count, int raw_cells,
                             global const param* phys, uint n, int row_len, global float* features) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  global const preal* grid = raw + (size_t)i * raw_cells;
  global float* row = features + (size_t)i * row_len;
  const preal lo = (preal)phys[PS_PHYS_WINDOW_MIN];
  const preal scale = (preal)255 / ((preal)phys[PS_PHYS_WINDOW_MAX] - lo);
  for (int f = 0; f < count; ++f) {
    preal t = 0;
    for (int k = first[f]; k < first[f + 1]; ++k) t += (preal)weights[k] * grid[cells[k]];
    row[columns[f]] = clamp((float)((t - lo) * scale), 0.0f, 255.0f);
  }
}
