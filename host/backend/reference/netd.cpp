#include <cmath>

#include "backend/reference/draws.h"
#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

namespace {

// Gaussian noise of `sd` kelvin rms on each value of f: cell p's table Gaussian of the
// counter generator's `stream` (docs/model/determinism.md), or under noise_draw irwin-hall
// the fast tier's draw.
void add_noise(const ViewScene& vs, Field& f, double sd, uint32_t stream) {
  if (sd <= 0) return;
  const bool fast = vs.draw == NoiseDraw::irwin_hall;
  for (int p = 0; p < f.width * f.height; ++p)
    f.v[p] += sd * (fast ? fast_gaussian(vs.model.seed, vs.index, stream, vs.view, p)
                         : table_gaussian(vs.model.seed, vs.index, stream, vs.view, p));
}

}  // namespace

// The MMW camera's NETD, per raw pixel, integrated over `frames` raw frames: the scene holds
// still while the camera averages them, so each frame adds its own draw of NETD / frames
// (frame 0 from the raw-noise stream, frame k from PS_STREAM_FRAME_NOISE + k).
// The block-mean noise model (the fast tier) takes the mean of the frames' draws as one draw
// of NETD / sqrt(frames) from frame 0's stream: the same normal distribution.
void netd(const ViewScene& vs, Field& f) {
  const int n = vs.model.frames;
  if (vs.frames_as_one) return add_noise(vs, f, vs.model.netd / std::sqrt(double(n)), kStreamRawNoise);
  for (int k = 0; k < n; ++k)
    add_noise(vs, f, vs.model.netd / n, k == 0 ? kStreamRawNoise : PS_STREAM_FRAME_NOISE + uint32_t(k));
}

// The IR camera's NETD, per view pixel.
void ir_netd(const ViewScene& vs, Field& f) { add_noise(vs, f, vs.model.ir_netd, kStreamIrNoise); }

}  // namespace portalsim::reference
