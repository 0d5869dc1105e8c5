// Percentile bootstrap intervals of ROC summaries, stratified (each draw resamples the
// positives and the negatives apart, keeping their counts) and paired (every score is
// summarised on the same draws). Draws come from Philox4x32-10 (scene/philox.h) under a
// stated seed, so the intervals are the same run to run and for any thread count.
#pragma once
#include <cstdint>
#include <vector>

#include "evaluate/roc.h"

namespace portalsim::evaluate {

struct Interval {
  double lo = 0, hi = 0;
};

struct BootstrapOptions {
  uint64_t seed = 1;
  int draws = 1000;
  double level = 0.95;
  unsigned threads = 1;
};

// Per score (orders[s], all over the same labels): the interval of the AUC and of each
// target's Pd. Percentiles are taken as numpy's default (linear between order statistics).
struct BootstrapIntervals {
  Interval auc;
  std::vector<Interval> pd;
};
std::vector<BootstrapIntervals> bootstrap(const std::vector<const ScoreOrder*>& orders,
                                          const std::vector<uint8_t>& label, const std::vector<double>& pfa,
                                          const BootstrapOptions& options);

// Draw `b`'s count of each row (kept for tests: the same seed gives the same counts).
std::vector<uint32_t> bootstrap_weights(const std::vector<uint8_t>& label, uint64_t seed, uint64_t b);

// The q-quantile (0..1) of `v` (sorted here), linear between order statistics.
double quantile(std::vector<double> v, double q);

}  // namespace portalsim::evaluate
