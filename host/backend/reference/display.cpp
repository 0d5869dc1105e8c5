#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

// The stored pixel: rounded half up, clamped to 8 bits.
void display(const ViewScene&, Field& f) {
  for (double& v : f.v) v = std::clamp(std::floor(v + 0.5), 0.0, 255.0);
}

}  // namespace portalsim::reference
