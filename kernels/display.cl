// Stage "display": the stored pixel, rounded half up and clamped to 8 bits.

kernel void stage_display(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  for (int x = 0; x < L.width; ++x) out[row0 + x] = to_pixel(field[row0 + x]);
}
