// `portalsim bench`'s measurements: every path's kernel, exact tier, plain loop, fp64
// reference and end-to-end rates, and the machine's memory and disk write rates, each
// repeated; the repetitions are interleaved (every measurement once, then again), so
// that a change in the machine's load falls on all of them alike.
#pragma once
#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "backend/opencl/runtime.h"
#include "speed/availability.h"
#include "speed/paths.h"

namespace portalsim::speed {

struct BenchOptions {
  bool quick = false;  // small batches and counts: seconds, for a check that it runs
  int repetitions = 3;
  std::string dir;                 // where end-to-end runs and the disk test write
  std::vector<std::string> paths;  // keys; empty = all
  bool progress = true;            // a progress line on stderr
};

// Sizes and timings for one run of the table.
struct Sizes {
  size_t features_batch, images_batch;              // kernel and plain loop
  size_t exact_features_batch, exact_images_batch;  // the exact tier: fp64 is slow on most devices
  size_t reference_batch;
  uint64_t features_count, images_count;  // end to end
  double min_seconds;                     // each timed measurement runs at least this long
  size_t memory_bytes, disk_bytes;
  static Sizes of(bool quick);
};

struct PathResult {
  SpeedPath path;
  size_t batch = 0, exact_batch = 0, reference_batch = 0;
  uint64_t end_to_end_count = 0;
  double output_bytes = 0;                       // per scenario, in kernel
  double written_bytes = 0;                      // per scenario, end to end
  std::map<Measure, std::vector<double>> rates;  // scenarios/s, one per repetition
  std::map<Measure, std::string> skipped;        // why a measure did not run
};

struct BenchReport {
  OpenCLDeviceInfo device;
  std::string date_utc, cpu, dir;
  double load[3] = {0, 0, 0};
  unsigned host_threads = 0;
  bool quick = false, disk_direct = false;
  int repetitions = 0;
  std::vector<double> memory_rates, disk_rates;  // bytes/s
  std::vector<PathResult> paths;
  std::string fp64_note;
};

// Measures on `rt`'s device. `device` is what the plan follows (normally rt->info()).
BenchReport run_bench(const BenchOptions& options, std::shared_ptr<OpenCLRuntime> rt, const OpenCLDeviceInfo& device);

double median(std::vector<double> v);  // 0 when empty

}  // namespace portalsim::speed
