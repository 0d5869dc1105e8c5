#include "calibrate/raw_grid.h"

#include <algorithm>
#include <cmath>

namespace portalsim::calibrate {

namespace {

// One view pixel's two raw neighbours and the far one's weight.
struct Tap {
  int c0, c1;
  double t;
};

std::vector<Tap> taps(int size, int raw) {
  std::vector<Tap> out(static_cast<size_t>(size));
  for (int x = 0; x < size; ++x) {
    const double u = std::clamp((x + 0.5) * raw / size - 0.5, 0.0, raw - 1.0);
    const int c0 = static_cast<int>(std::floor(u));
    out[x] = {c0, std::min(c0 + 1, raw - 1), u - c0};
  }
  return out;
}

// Weighted least squares of one line y (weights w, 0 or 1) on the interpolation's columns:
// the normal equations are tridiagonal. Returns the weighted square residual; z gets the
// raw values.
double fit_line(const std::vector<Tap>& tp, int raw, const double* y, const double* w, std::vector<double>& z) {
  std::vector<double> d(raw, 0.0), e(raw, 0.0), r(raw, 0.0);  // e[k]: entry (k, k + 1)
  for (size_t x = 0; x < tp.size(); ++x) {
    if (w[x] == 0) continue;
    const Tap& t = tp[x];
    const double a = 1.0 - t.t, b = t.t;
    if (t.c0 == t.c1) {
      d[t.c0] += 1.0;
      r[t.c0] += y[x];
      continue;
    }
    d[t.c0] += a * a;
    d[t.c1] += b * b;
    e[t.c0] += a * b;
    r[t.c0] += a * y[x];
    r[t.c1] += b * y[x];
  }
  // A small ridge keeps a raw pixel that no kept view pixel reaches at zero.
  for (double& v : d) v += 1e-9;
  // Thomas's algorithm.
  std::vector<double> c(raw, 0.0);
  z.assign(raw, 0.0);
  for (int k = 0; k < raw; ++k) {
    const double m = d[k] - (k > 0 ? e[k - 1] * c[k - 1] : 0.0);
    c[k] = e[k] / m;
    z[k] = (r[k] - (k > 0 ? e[k - 1] * z[k - 1] : 0.0)) / m;
  }
  for (int k = raw - 2; k >= 0; --k) z[k] -= c[k] * z[k + 1];
  double ss = 0;
  for (size_t x = 0; x < tp.size(); ++x) {
    if (w[x] == 0) continue;
    const double f = (1.0 - tp[x].t) * z[tp[x].c0] + tp[x].t * z[tp[x].c1] - y[x];
    ss += f * f;
  }
  return ss;
}

bool clipped(uint8_t v) { return v == 0 || v == 255; }

}  // namespace

GridAxis raw_grid_axis(const std::vector<const std::vector<uint8_t>*>& images, int width, int height, bool along_x) {
  const int size = along_x ? width : height, lines = along_x ? height : width;
  // Every 4th line is plenty: a wrong grid leaves its residual on every line.
  std::vector<std::vector<double>> ys, ws;
  for (const auto* img : images)
    for (int l = 0; l < lines; l += 4) {
      std::vector<double> y(size), w(size);
      for (int i = 0; i < size; ++i) {
        const uint8_t v =
            along_x ? (*img)[static_cast<size_t>(l) * width + i] : (*img)[static_cast<size_t>(i) * width + l];
        y[i] = v;
        w[i] = clipped(v) ? 0.0 : 1.0;
      }
      ys.push_back(std::move(y));
      ws.push_back(std::move(w));
    }
  double kept = 0;
  for (const auto& w : ws)
    for (double v : w) kept += v;
  GridAxis g;
  g.raw = size;
  std::vector<double> z;
  for (int n = 1; n <= size; ++n) {
    const std::vector<Tap> tp = taps(size, n);
    double ss = 0;
    for (size_t k = 0; k < ys.size(); ++k) ss += fit_line(tp, n, ys[k].data(), ws[k].data(), z);
    const double ms = kept > 0 ? ss / kept : 0.0;
    // Rounding to whole levels leaves 1/12 gray^2 per pixel, less the share the fit
    // absorbs (n of size degrees of freedom); 1.5 times that allows for rounding's own
    // correlations along smooth rows (measured 0.055 at 28 of 200; a grid of 27 or 29
    // leaves 0.17 or more on noise-free captures).
    const double bound = 0.125 * (1.0 - double(n) / size) + 0.005;
    g.ms.push_back(ms);
    g.bound.push_back(bound);
    if (ms <= bound && g.raw == size) g.raw = n;
    if (g.raw < size && n >= g.raw + 8) break;  // the residual curve past the answer, for the report
  }
  return g;
}

void recover_raw(const std::vector<uint8_t>& img, int width, int height, int raw_w, int raw_h, std::vector<double>& raw,
                 std::vector<char>& valid) {
  const std::vector<Tap> tx = taps(width, raw_w), ty = taps(height, raw_h);
  std::vector<double> mid(static_cast<size_t>(height) * raw_w), y(width), w(width), z;
  for (int r = 0; r < height; ++r) {
    for (int x = 0; x < width; ++x) {
      const uint8_t v = img[static_cast<size_t>(r) * width + x];
      y[x] = v;
      w[x] = clipped(v) ? 0.0 : 1.0;
    }
    fit_line(tx, raw_w, y.data(), w.data(), z);
    for (int c = 0; c < raw_w; ++c) mid[static_cast<size_t>(r) * raw_w + c] = z[c];
  }
  raw.assign(static_cast<size_t>(raw_w) * raw_h, 0.0);
  std::vector<double> col(height), ones(height, 1.0);
  for (int c = 0; c < raw_w; ++c) {
    for (int r = 0; r < height; ++r) col[r] = mid[static_cast<size_t>(r) * raw_w + c];
    fit_line(ty, raw_h, col.data(), ones.data(), z);
    for (int r = 0; r < raw_h; ++r) raw[static_cast<size_t>(r) * raw_w + c] = z[r];
  }
  valid.assign(raw.size(), 1);
  for (int yy = 0; yy < height; ++yy)
    for (int x = 0; x < width; ++x)
      if (clipped(img[static_cast<size_t>(yy) * width + x]))
        for (int r : {ty[yy].c0, ty[yy].c1})
          for (int c : {tx[x].c0, tx[x].c1}) valid[static_cast<size_t>(r) * raw_w + c] = 0;
}

double rounding_variance(int width, int height, int raw_w, int raw_h) {
  // Mean diagonal of (A^T A)^-1 along each axis: the fitted raw values of view pixel x's
  // unit line are column x of A^+, and ((A^T A)^-1)_kk is the sum of row k of A^+ squared.
  auto mean_diag = [](int size, int raw) {
    const std::vector<Tap> tp = taps(size, raw);
    std::vector<double> ones(size, 1.0), y(size), z;
    double sum = 0;
    std::vector<double> acc(raw, 0.0);
    for (int x = 0; x < size; ++x) {
      std::fill(y.begin(), y.end(), 0.0);
      y[x] = 1.0;
      fit_line(tp, raw, y.data(), ones.data(), z);
      for (int k = 0; k < raw; ++k) acc[k] += z[k] * z[k];
    }
    for (double v : acc) sum += v;
    return sum / raw;
  };
  return mean_diag(width, raw_w) * mean_diag(height, raw_h) / 12.0;
}

}  // namespace portalsim::calibrate
