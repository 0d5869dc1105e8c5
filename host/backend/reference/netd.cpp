#include "backend/reference/draws.h"
#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

namespace {

// Gaussian noise of `sd` kelvin rms on each value of f: cell p's table Gaussian of the
// counter generator's `stream` (docs/model/determinism.md).
void add_noise(const ViewScene& vs, Field& f, double sd, uint32_t stream) {
  if (sd <= 0) return;
  for (int p = 0; p < f.width * f.height; ++p)
    f.v[p] += sd * table_gaussian(vs.model.seed, vs.index, stream, vs.view, p);
}

}  // namespace

// The MMW camera's NETD, per raw pixel.
void netd(const ViewScene& vs, Field& f) { add_noise(vs, f, vs.model.netd, kStreamRawNoise); }

// The IR camera's NETD, per view pixel.
void ir_netd(const ViewScene& vs, Field& f) { add_noise(vs, f, vs.model.ir_netd, kStreamIrNoise); }

}  // namespace portalsim::reference
