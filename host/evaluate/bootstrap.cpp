#include "evaluate/bootstrap.h"

#include <algorithm>
#include <cmath>

#include "base/parallel.h"
#include "scene/philox.h"

namespace portalsim::evaluate {

namespace {
// The bootstrap's Philox stream, apart from the generator's (kernels/contract.h) by value.
constexpr uint32_t kStreamBootstrap = 0x424f4f54;  // "BOOT"
}  // namespace

std::vector<uint32_t> bootstrap_weights(const std::vector<uint8_t>& label, uint64_t seed, uint64_t b) {
  std::vector<uint32_t> positives, negatives;
  for (uint32_t r = 0; r < label.size(); ++r) (label[r] ? positives : negatives).push_back(r);
  std::vector<uint32_t> w(label.size(), 0);
  uint32_t element = 0;
  for (const std::vector<uint32_t>* rows : {&positives, &negatives}) {
    const uint32_t n = static_cast<uint32_t>(rows->size());
    for (uint32_t k = 0; k < n; k += 4, ++element) {
      const Philox4 r = draw(seed, b, kStreamBootstrap, element);
      for (uint32_t j = 0; j < 4 && k + j < n; ++j) ++w[(*rows)[below(r[j], n)]];
    }
  }
  return w;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double at = q * static_cast<double>(v.size() - 1);
  const size_t i = static_cast<size_t>(std::floor(at));
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (at - static_cast<double>(i)) * (v[i + 1] - v[i]);
}

std::vector<BootstrapIntervals> bootstrap(const std::vector<const ScoreOrder*>& orders,
                                          const std::vector<uint8_t>& label, const std::vector<double>& pfa,
                                          const BootstrapOptions& o) {
  const size_t draws = static_cast<size_t>(std::max(0, o.draws));
  // summaries[d][s]: draw d's summary of score s
  std::vector<std::vector<RocSummary>> summaries(draws);
  parallel_for(draws, o.threads, [&](size_t begin, size_t end) {
    for (size_t d = begin; d < end; ++d) {
      const std::vector<uint32_t> w = bootstrap_weights(label, o.seed, d);
      for (const ScoreOrder* order : orders) summaries[d].push_back(summarize(*order, label, &w, pfa));
    }
  });
  const double tail = (1 - o.level) / 2;
  std::vector<BootstrapIntervals> out(orders.size());
  std::vector<double> v(draws);
  for (size_t s = 0; s < orders.size(); ++s) {
    for (size_t d = 0; d < draws; ++d) v[d] = summaries[d][s].auc;
    out[s].auc = {quantile(v, tail), quantile(v, 1 - tail)};
    for (size_t k = 0; k < pfa.size(); ++k) {
      for (size_t d = 0; d < draws; ++d) v[d] = summaries[d][s].pd[k].pd;
      out[s].pd.push_back({quantile(v, tail), quantile(v, 1 - tail)});
    }
  }
  return out;
}

}  // namespace portalsim::evaluate
