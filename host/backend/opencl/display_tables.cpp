#include "backend/opencl/display_tables.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/plain_math.h"

namespace portalsim::opencl {

namespace {

// Keys' cubic convolution kernel, a = -1/2.
double cubic(double s) {
  s = std::fabs(s);
  return s <= 1 ? (1.5 * s - 2.5) * s * s + 1 : s < 2 ? ((-0.5 * s + 2.5) * s - 4) * s + 2 : 0.0;
}

// Each of `size` view pixels' weights of the `raw` cells along one axis, w[x * raw + c]:
// the filter's taps about the pixel centre's raw coordinate (held inside the outer
// centres; taps past an edge on the edge cell), then a Gaussian of `sigma` view pixels
// over +-4 sigma, normalised, edges held.
std::vector<double> axis(int size, int raw, DisplayFilter filter, double sigma) {
  std::vector<double> w(static_cast<size_t>(size) * raw, 0.0);
  for (int x = 0; x < size; ++x) {
    const double u = std::clamp((x + 0.5) * raw / size - 0.5, 0.0, raw - 1.0);
    const int c0 = static_cast<int>(std::floor(u));
    const double t = u - c0;
    double* wx = &w[static_cast<size_t>(x) * raw];
    const auto add = [&](int c, double v) { wx[std::clamp(c, 0, raw - 1)] += v; };
    if (filter == DisplayFilter::bilinear) {
      add(c0, 1 - t);
      add(c0 + 1, t);
    } else {
      for (int k = -1; k <= 2; ++k) add(c0 + k, cubic(k - t));
    }
  }
  if (sigma <= 0) return w;
  const int R = static_cast<int>(std::ceil(4.0 * sigma));
  std::vector<double> g(2 * size_t(R) + 1);
  double total = 0;
  for (int d = -R; d <= R; ++d) total += g[size_t(d + R)] = plain::exp(-0.5 * d * d / (sigma * sigma));
  std::vector<double> s(w.size(), 0.0);
  for (int x = 0; x < size; ++x)
    for (int d = -R; d <= R; ++d) {
      const double* from = &w[static_cast<size_t>(std::clamp(x + d, 0, size - 1)) * raw];
      for (int c = 0; c < raw; ++c) s[static_cast<size_t>(x) * raw + c] += g[size_t(d + R)] / total * from[c];
    }
  return s;
}

// The first and last cell with a weight in pixels [x0, x1) of w.
void band(const std::vector<double>& w, int raw, int x0, int x1, std::vector<double>& out) {
  int lo = raw - 1, hi = 0;
  for (int x = x0; x < x1; ++x)
    for (int c = 0; c < raw; ++c)
      if (w[static_cast<size_t>(x) * raw + c] != 0) lo = std::min(lo, c), hi = std::max(hi, c);
  out.push_back(std::min(lo, hi));
  out.push_back(hi);
}

}  // namespace

DisplayTables append_display_tables(std::vector<double>& p, const ModelSettings& m, int W, int H, int RW, int RH) {
  const auto append = [&](const std::vector<double>& v) {
    if (p.size() + v.size() > 0x7fffffffu) throw std::runtime_error("display tables exceed 2^31 values");
    const auto at = static_cast<int32_t>(p.size());
    p.insert(p.end(), v.begin(), v.end());
    return at;
  };
  DisplayTables t{};
  t.stride = (W + 15) / 16 * 16;
  const std::vector<double> wx = axis(W, RW, m.display_filter, m.smooth);
  const std::vector<double> wy = axis(H, RH, m.display_filter, m.smooth);
  // Columns: raw column c's weights of the view columns, padded with zeros to the stride;
  // the band of each run of 16 view columns.
  std::vector<double> dx(static_cast<size_t>(RW) * t.stride, 0.0), dxband, dyband;
  for (int c = 0; c < RW; ++c)
    for (int x = 0; x < W; ++x) dx[static_cast<size_t>(c) * t.stride + x] = wx[static_cast<size_t>(x) * RW + c];
  for (int x = 0; x < t.stride; x += 16) band(wx, RW, std::min(x, W), std::min(x + 16, W), dxband);
  for (int y = 0; y < H; ++y) band(wy, RH, y, y + 1, dyband);
  t.dx = append(dx);
  t.dxband = append(dxband);
  t.dy = append(wy);
  t.dyband = append(dyband);
  return t;
}

int kernel_frames(const Plan& plan, const ModelSettings& m) { return plan.frames_approximated() ? 1 : m.frames; }

double kernel_netd(const Plan& plan, const ModelSettings& m) {
  return plan.frames_approximated() ? m.netd / std::sqrt(double(m.frames)) : m.netd;
}

MmwNoise mmw_noise(const Plan& plan, const ModelSettings& m) {
  const DrawnRange &netd = m.drawn[PS_DRAWN_NETD], &frames = m.drawn[PS_DRAWN_FRAMES];
  if (!netd.varies() && !frames.varies()) {
    const double sd = kernel_netd(plan, m);
    return {.netd_lo = sd, .netd_hi = sd, .frames_lo = m.frames, .frames_hi = m.frames};
  }
  return {.netd_lo = m.netd,
          .netd_hi = netd.varies() ? netd.hi : m.netd,
          .frames_lo = m.frames,
          .frames_hi = frames.varies() ? static_cast<int>(frames.hi) : m.frames,
          .as_one = plan.frames_approximated()};
}

}  // namespace portalsim::opencl
