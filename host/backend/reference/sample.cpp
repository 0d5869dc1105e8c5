#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"

namespace portalsim::reference {

namespace {
// The length of [a, b) that pixel p, [p, p + 1), covers.
double overlap(int p, double a, double b) { return std::max(0.0, std::min(p + 1.0, b) - std::max(double(p), a)); }
}  // namespace

// Raw pixel (c, r) is the mean of the field over its footprint,
// [c W / RW, (c + 1) W / RW) x [r H / RH, (r + 1) H / RH), partial pixels by area.
void sample(const ViewScene& vs, Field& f) {
  const int W = f.width, H = f.height, RW = vs.model.raw_width, RH = vs.model.raw_height;
  const double sx = double(W) / RW, sy = double(H) / RH;
  Field raw;
  raw.width = RW;
  raw.height = RH;
  raw.v.assign(static_cast<size_t>(RW) * RH, 0.0);
  for (int r = 0; r < RH; ++r)
    for (int c = 0; c < RW; ++c) {
      double acc = 0;
      // Only the pixels the footprint can touch; overlap() is 0 for the rest.
      const int y0 = static_cast<int>(std::floor(r * sy)), y1 = std::min(H, static_cast<int>(std::ceil((r + 1) * sy)));
      const int x0 = static_cast<int>(std::floor(c * sx)), x1 = std::min(W, static_cast<int>(std::ceil((c + 1) * sx)));
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
          acc += overlap(y, r * sy, (r + 1) * sy) * overlap(x, c * sx, (c + 1) * sx) * f.at(x, y);
      raw.at(c, r) = acc / (sx * sy);
    }
  f = std::move(raw);
}

}  // namespace portalsim::reference
