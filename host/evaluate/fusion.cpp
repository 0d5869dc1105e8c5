#include "evaluate/fusion.h"

#include <algorithm>

namespace portalsim::evaluate {

const char* rule_name(DecisionRule r) {
  return r == DecisionRule::any ? "or" : r == DecisionRule::all ? "and" : "majority";
}

std::vector<double> negative_exceedance(const std::vector<double>& score, const std::vector<uint8_t>& label) {
  std::vector<double> negatives;
  for (size_t i = 0; i < score.size(); ++i)
    if (!label[i]) negatives.push_back(score[i]);
  std::sort(negatives.begin(), negatives.end());
  std::vector<double> u(score.size(), 0.0);
  if (negatives.empty()) return u;
  for (size_t i = 0; i < score.size(); ++i) {
    const auto at_least = negatives.end() - std::lower_bound(negatives.begin(), negatives.end(), score[i]);
    u[i] = static_cast<double>(at_least) / static_cast<double>(negatives.size());
  }
  return u;
}

std::vector<double> decision_fusion(const std::vector<std::vector<double>>& scores, const std::vector<uint8_t>& label,
                                    DecisionRule rule) {
  const size_t n = scores.empty() ? 0 : scores[0].size();
  std::vector<std::vector<double>> u;
  for (const auto& s : scores) u.push_back(negative_exceedance(s, label));
  // The order statistic that decides: OR the smallest u, AND the largest, majority the
  // (m/2 + 1)-th smallest of m.
  const size_t m = scores.size();
  const size_t k = rule == DecisionRule::any ? 0 : rule == DecisionRule::all ? m - 1 : m / 2;
  std::vector<double> fused(n), row(m);
  for (size_t i = 0; i < n; ++i) {
    for (size_t s = 0; s < m; ++s) row[s] = u[s][i];
    std::nth_element(row.begin(), row.begin() + static_cast<long>(k), row.end());
    fused[i] = -row[k];
  }
  return fused;
}

}  // namespace portalsim::evaluate
