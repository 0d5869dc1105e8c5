// ROC curves, their area, Pd at a stated Pfa and the log loss: the numbers `portalsim
// evaluate` reports, computed one way for the point estimate and for every bootstrap draw.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace portalsim::evaluate {

// Rows ordered by score, highest first, cut into groups of equal score: one ROC point per
// group (a threshold at that score alarms on every row scoring at least it).
struct ScoreOrder {
  std::vector<uint32_t> rows;       // by score, descending; ties by row
  std::vector<uint32_t> group_end;  // rows[group_end[g-1] .. group_end[g]) share a score
  std::vector<double> group_score;
};
ScoreOrder order_scores(const std::vector<double>& score);

// Pd at a target Pfa: the largest Pd among the ROC's points whose Pfa is at most the target
// (an operating point a threshold reaches, never an interpolation), and that point.
struct PdAtPfa {
  double target = 0, pd = 0, pfa = 0;
  double threshold = 0;  // alarm when score >= threshold; +infinity: the point (0, 0)
};

struct RocSummary {
  double auc = 0;
  std::vector<PdAtPfa> pd;  // one per target
};

// The ROC of `order` with row weights (counts of a bootstrap draw; null: every row once).
// AUC by the trapezoid rule over the points, which counts a tie between a positive and a
// negative as half (the Mann-Whitney statistic). `pfa` targets in [0, 1].
RocSummary summarize(const ScoreOrder& order, const std::vector<uint8_t>& label, const std::vector<uint32_t>* weight,
                     const std::vector<double>& pfa);

// The curve itself: (Pfa, Pd) from (0, 0) through one point per distinct score, as
// scikit-learn's roc_curve(drop_intermediate=False) gives it; threshold[0] is +infinity.
struct RocCurve {
  std::vector<double> pfa, pd, threshold;
};
RocCurve roc_curve(const ScoreOrder& order, const std::vector<uint8_t>& label);

// Mean of -(y log p + (1 - y) log(1 - p)), p clipped to [1e-15, 1 - 1e-15] (the Kaggle
// Passenger Screening Challenge's log loss, as scikit-learn's log_loss).
double log_loss(const std::vector<double>& p, const std::vector<uint8_t>& label);

}  // namespace portalsim::evaluate
