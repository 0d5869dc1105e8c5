// Block averaging (thesis 5.6): means of n x n blocks of both MMW views, then of each
// region's rectangle. Sums are exact integers; partial edge blocks average the pixels
// they hold.

// One work-item per (scenario, view, block). Features row: upper blocks, lower blocks,
// region means.
kernel void pool_blocks(global const uchar* upper, global const uchar* lower, uint n, int W, int H, int block,
                        int bx_count, int by_count, int row_len, global float* features) {
  const size_t gid = get_global_id(0);
  const int per_view = bx_count * by_count;
  const uint i = (uint)(gid / (size_t)(2 * per_view));
  if (i >= n) return;
  const int rem = (int)(gid % (size_t)(2 * per_view));
  const int view = rem / per_view, b = rem % per_view;
  const int x0 = (b % bx_count) * block, y0 = (b / bx_count) * block;
  const int x1 = min(x0 + block, W), y1 = min(y0 + block, H);
  global const uchar* img = (view ? lower : upper) + (size_t)i * W * H;
  uint sum = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) sum += img[y * W + x];
  features[(size_t)i * row_len + rem] = (float)sum / (float)((x1 - x0) * (y1 - y0));
}

// One work-item per (scenario, region). rects: int4 (x, y, w, h) in the region's MMW view.
kernel void pool_regions(global const uchar* upper, global const uchar* lower, uint n, int W, int H,
                         global const int4* rects, int offset, int row_len, global float* features) {
  const size_t gid = get_global_id(0);
  const uint i = (uint)(gid / 13);
  if (i >= n) return;
  const int r = (int)(gid % 13);
  const int4 rc = rects[r];
  global const uchar* img = (r < 6 ? upper : lower) + (size_t)i * W * H;
  uint sum = 0;
  for (int y = rc.y; y < rc.y + rc.w; ++y)
    for (int x = rc.x; x < rc.x + rc.z; ++x) sum += img[y * W + x];
  features[(size_t)i * row_len + offset + r] = (float)sum / (float)(rc.z * rc.w);
}
