#include <cmath>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

// Thesis 4.2: the scenario's noise pattern, drawn once per scenario, centred on every
// object of a view that takes pattern noise: v += gain (tile - 128).
void pattern_noise(const ViewScene& vs, Field& f) {
  if (!vs.sensor.pattern_noise || !vs.model.pattern_noise || vs.placed.empty()) return;
  const uint32_t k =
      below(draw(vs.model.seed, vs.index, kStreamNoisePattern, 0)[0], static_cast<uint32_t>(vs.assets.noise.size()));
  const Image& tile = vs.assets.noise[k];
  const double gain = vs.cat.noise[k].gain;
  for (const Placed& p : vs.placed) {
    const int tx0 =
        p.x0 + static_cast<int>(std::floor(p.sprite->width / 2.0)) - static_cast<int>(std::floor(tile.width / 2.0));
    const int ty0 =
        p.y0 + static_cast<int>(std::floor(p.sprite->height / 2.0)) - static_cast<int>(std::floor(tile.height / 2.0));
    for (int ty = 0; ty < tile.height; ++ty)
      for (int tx = 0; tx < tile.width; ++tx) {
        const int x = tx0 + tx, y = ty0 + ty;
        if (x < 0 || y < 0 || x >= f.width || y >= f.height) continue;
        f.at(x, y) += gain * (tile.at(tx, ty) - 128.0);
      }
  }
}

}  // namespace portalsim::reference
