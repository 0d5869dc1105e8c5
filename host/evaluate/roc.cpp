#include "evaluate/roc.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace portalsim::evaluate {

ScoreOrder order_scores(const std::vector<double>& score) {
  ScoreOrder o;
  o.rows.resize(score.size());
  std::iota(o.rows.begin(), o.rows.end(), 0u);
  std::stable_sort(o.rows.begin(), o.rows.end(), [&](uint32_t a, uint32_t b) { return score[a] > score[b]; });
  for (size_t i = 0; i < o.rows.size(); ++i)
    if (i + 1 == o.rows.size() || score[o.rows[i + 1]] != score[o.rows[i]]) {
      o.group_end.push_back(static_cast<uint32_t>(i + 1));
      o.group_score.push_back(score[o.rows[i]]);
    }
  return o;
}

RocSummary summarize(const ScoreOrder& order, const std::vector<uint8_t>& label, const std::vector<uint32_t>* weight,
                     const std::vector<double>& pfa) {
  double positives = 0, negatives = 0;
  for (uint32_t r : order.rows) {
    const double w = weight ? (*weight)[r] : 1.0;
    (label[r] ? positives : negatives) += w;
  }
  RocSummary s;
  s.pd.resize(pfa.size());
  for (size_t k = 0; k < pfa.size(); ++k) {
    s.pd[k].target = pfa[k];
    s.pd[k].threshold = std::numeric_limits<double>::infinity();
  }
  if (positives == 0 || negatives == 0) return s;
  double tp = 0, fp = 0, area = 0;
  size_t begin = 0;
  for (size_t g = 0; g < order.group_end.size(); ++g) {
    const double tp0 = tp, fp0 = fp;
    for (size_t i = begin; i < order.group_end[g]; ++i) {
      const uint32_t r = order.rows[i];
      const double w = weight ? (*weight)[r] : 1.0;
      (label[r] ? tp : fp) += w;
    }
    begin = order.group_end[g];
    area += (fp - fp0) * (tp + tp0) / 2;
    const double x = fp / negatives, y = tp / positives;
    for (PdAtPfa& p : s.pd)
      if (x <= p.target && y > p.pd) {
        p.pd = y;
        p.pfa = x;
        p.threshold = order.group_score[g];
      }
  }
  s.auc = area / (positives * negatives);
  return s;
}

RocCurve roc_curve(const ScoreOrder& order, const std::vector<uint8_t>& label) {
  RocCurve c;
  double positives = 0, negatives = 0;
  for (uint8_t y : label) (y ? positives : negatives) += 1;
  c.pfa.push_back(0);
  c.pd.push_back(0);
  c.threshold.push_back(std::numeric_limits<double>::infinity());
  double tp = 0, fp = 0;
  size_t begin = 0;
  for (size_t g = 0; g < order.group_end.size(); ++g) {
    for (size_t i = begin; i < order.group_end[g]; ++i) (label[order.rows[i]] ? tp : fp) += 1;
    begin = order.group_end[g];
    c.pfa.push_back(negatives > 0 ? fp / negatives : 0);
    c.pd.push_back(positives > 0 ? tp / positives : 0);
    c.threshold.push_back(order.group_score[g]);
  }
  return c;
}

double log_loss(const std::vector<double>& p, const std::vector<uint8_t>& label) {
  constexpr double eps = 1e-15;
  double sum = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double q = std::clamp(p[i], eps, 1 - eps);
    sum -= label[i] ? std::log(q) : std::log(1 - q);
  }
  return p.empty() ? 0 : sum / static_cast<double>(p.size());
}

}  // namespace portalsim::evaluate
