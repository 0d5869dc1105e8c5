#include <algorithm>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

void metal(const Catalogue& cat, const ModelSettings& m, const Scenario& s, uint64_t index, uint8_t* zones) {
  const int noise = m.metal_noise;
  for (int z = 0; z < cat.zones; ++z) {
    int sum = 0;
    for (int r = 0; r < cat.region_count(); ++r)
      if (s.objects[r] != kNoObject) sum += cat.influence[cat.object_of(s.objects[r]).metal][r][z];
    int value = cat.subjects[s.subject].base_zones[z] - sum;
    if (noise > 0 && sum > 0) {
      const Philox4 r = draw(m.seed, index, kStreamMetalNoise, static_cast<uint32_t>(z));
      value += static_cast<int>(below(r[0], noise + 1)) - static_cast<int>(below(r[1], noise + 1));
    }
    zones[z] = static_cast<uint8_t>(std::clamp(value, 1, 200));
  }
}

}  // namespace portalsim::reference
