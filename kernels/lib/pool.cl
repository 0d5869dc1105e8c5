// Helpers (kernels/lib/): the mean of a block or region of pixels (pool, pool_sparse).

// A mean of 8-bit pixels: whole part by integer division, remainder in float, so a flat
// area's mean is exact even when -cl-fast-relaxed-math makes float division approximate
// (host/sink/folder_reader.cpp computes the same expression). Clamped to the pixel range.
inline float mean_of(uint sum, int count) {
  const uint q = sum / (uint)count, r = sum % (uint)count;
  return clamp((float)q + (float)r / (float)count, 0.0f, 255.0f);
}
