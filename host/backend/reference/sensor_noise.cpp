#include "backend/reference/draws.h"
#include "backend/reference/stages.h"

namespace portalsim::reference {

// Per-pixel Gaussian sensor noise, sigma gray levels: Box-Muller over the counter
// generator, one draw per pixel pair (2k, 2k+1) of the view; or, under noise_draw irwin-hall,
// the Irwin-Hall draw of each pixel (docs/model/determinism.md).
void sensor_noise(const ViewScene& vs, Field& f) {
  const double sigma = vs.model.pixel_sigma;
  if (sigma <= 0) return;
  const int pixels = f.width * f.height;
  const bool ih = vs.draw == NoiseDraw::irwin_hall;
  for (int p = 0; p < pixels; ++p)
    f.v[p] += sigma * (ih ? pixel_irwin_hall(vs.model.seed, vs.index, vs.view, p)
                          : pixel_gaussian(vs.model.seed, vs.index, vs.view, p));
}

}  // namespace portalsim::reference
