// The machine's own limits, measured by `portalsim bench` beside the paths: how fast
// memory and the output folder's disk take fresh bytes.
#pragma once
#include <cstddef>
#include <string>

namespace portalsim::speed {

// Bytes/s of writing a `bytes`-sized buffer (beyond the caches) with memset on
// `threads` threads, each its own slice; the pages are touched once before timing.
double memory_write_rate(size_t bytes, unsigned threads);

struct DiskRate {
  double bytes_per_s = 0;
  bool direct = false;  // O_DIRECT, as dd oflag=direct; else written, then fsync (tmpfs has no direct I/O)
};
// Writes `bytes` of fresh data to a new file in `dir` in 16 MiB blocks, then removes it.
// Throws OutputError when dir cannot take the file.
DiskRate disk_write_rate(const std::string& dir, size_t bytes);

}  // namespace portalsim::speed
