// One evaluation of a labelled feature table: out-of-fold scores per sensor and fused, their
// ROC summaries with bootstrap intervals, and per region the "threat in this region" scores
// and the challenge's log loss. The command line (cli/evaluate.cpp) reads the table and
// writes the report (evaluate/report.h).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evaluate/bootstrap.h"
#include "evaluate/classifiers.h"
#include "evaluate/roc.h"

namespace portalsim::evaluate {

struct Dataset {
  std::string source;                // the table it came from, for the report
  Matrix x;                          // every feature column
  std::vector<std::string> columns;  // their names
  std::vector<std::string> sensor;   // per column: the sensor it belongs to ("upper", "metal", ...)
  std::vector<uint8_t> label;        // 1 threat
  // Per region (may be none): its name, its rows' labels and the columns its model reads.
  struct Region {
    std::string name;
    std::vector<uint8_t> label;
    std::vector<size_t> columns;
  };
  std::vector<Region> regions;
};

struct Options {
  int folds = 5;
  ClassifierKind classifier = ClassifierKind::trees;
  std::vector<double> pfa{0.01, 0.05, 0.1};
  uint64_t seed = 1;  // folds and bootstrap
  int bootstrap = 1000;
  unsigned threads = 1;
};

// A score and what it gives: AUC and Pd at each target Pfa, with intervals.
struct Scored {
  std::string name;  // "metal", "upper", ..., "fused_features", "fused_or", ...
  std::string how;   // one line: what the score is
  std::vector<double> score;
  ScoreOrder order;
  RocSummary summary;
  BootstrapIntervals interval;
};

struct RegionResult {
  std::string name;
  size_t positives = 0;
  std::optional<Scored> scored;  // none where the region holds no threat (or only threats)
  std::vector<double> probability;
  double log_loss = 0, baseline_log_loss = 0;  // baseline: the region's share of threats as p
};

struct Timing {
  double training = 0, bootstrap = 0;
};

struct Evaluation {
  std::vector<int> fold;
  std::vector<Scored> entries;  // sensors in the table's order, then the fusions
  std::vector<RegionResult> regions;
  double mean_log_loss = 0, baseline_mean_log_loss = 0;
  Timing timing;
};

// The sensors of the table, in the order their first column appears.
std::vector<std::string> sensors_of(const Dataset& d);

// Checks the data (two classes, at least `folds` rows of each) and runs everything; throws
// InputError naming the table.
Evaluation run_evaluation(const Dataset& d, const Options& o);

}  // namespace portalsim::evaluate
