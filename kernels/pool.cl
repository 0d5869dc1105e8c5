// Stage "pool" (thesis 5.6): means of n x n blocks of each pooled view, then of each
// region's rectangle. Sums are exact integers; partial edge blocks average the pixels
// they hold. Launched once per pooled view.

// One work-item per (scenario, block) of one view; its blocks start at column `offset`.
kernel void pool_blocks(global const uchar* img, uint n, int W, int H, int block, int bx_count, int by_count,
                        int offset, int row_len, global float* features) {
  const size_t gid = get_global_id(0);
  const int per_view = bx_count * by_count;
  const uint i = (uint)(gid / (size_t)per_view);
  if (i >= n) return;
  const int b = (int)(gid % (size_t)per_view);
  const int x0 = (b % bx_count) * block, y0 = (b / bx_count) * block;
  const int x1 = min(x0 + block, W), y1 = min(y0 + block, H);
  img += (size_t)i * W * H;
  uint sum = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) sum += img[y * W + x];
  features[(size_t)i * row_len + offset + b] = mean_of(sum, (x1 - x0) * (y1 - y0));
}

// One work-item per (scenario, region); regions outside `region_mask` belong to another
// view. rects: int4 (x, y, w, h) of each region in its view.
kernel void pool_regions(global const uchar* img, uint n, int W, int H, global const int4* rects, uint region_mask,
                         int offset, int row_len, global float* features) {
  const size_t gid = get_global_id(0);
  const uint i = (uint)(gid / PS_REGIONS);
  if (i >= n) return;
  const int r = (int)(gid % PS_REGIONS);
  if (!((region_mask >> r) & 1u)) return;
  const int4 rc = rects[r];
  img += (size_t)i * W * H;
  uint sum = 0;
  for (int y = rc.y; y < rc.y + rc.w; ++y)
    for (int x = rc.x; x < rc.x + rc.z; ++x) sum += img[y * W + x];
  features[(size_t)i * row_len + offset + r] = mean_of(sum, rc.z * rc.w);
}
