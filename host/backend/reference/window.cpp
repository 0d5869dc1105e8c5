#include <algorithm>

#include "backend/reference/stages.h"
#include "contract.h"

namespace portalsim::reference {

// The automatic window: the raw grid's PS_WINDOW_LOW_PERMILLE and PS_WINDOW_HIGH_PERMILLE
// order statistics (1st and 99th percentiles) become the fixed window's ends, so that
// mmw_display shows them as gray 0 and 255; at least PS_WINDOW_MIN_SPAN kelvin wide. A
// camera's automatic gain does the same to each frame it shows. The fixed window leaves f.
void window(const ViewScene& vs, Field& f) {
  const ModelSettings& m = vs.model;
  if (!m.window_auto) return;
  std::vector<double> sorted = f.v;
  std::sort(sorted.begin(), sorted.end());
  // Order statistic q (thousandths): rank round(q (cells - 1) / 1000).
  const auto rank = [&](int q) { return sorted[(q * (sorted.size() - 1) + 500) / 1000]; };
  const double lo = rank(PS_WINDOW_LOW_PERMILLE);
  const double hi = std::max(rank(PS_WINDOW_HIGH_PERMILLE), lo + PS_WINDOW_MIN_SPAN);
  for (double& t : f.v) t = m.window_lo + (t - lo) * (m.window_hi - m.window_lo) / (hi - lo);
}

}  // namespace portalsim::reference
