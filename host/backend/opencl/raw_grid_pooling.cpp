#include "backend/opencl/raw_grid_pooling.h"

#include <algorithm>
#include <cmath>

namespace portalsim {

namespace {

// Each pixel's interpolation weights along one axis (size pixels over raw cells), as
// stage_mmw_display samples: centre (p + 1/2) raw / size - 1/2, held inside [0, raw - 1].
std::vector<std::vector<double>> axis_weights(int size, int raw) {
  std::vector<std::vector<double>> w(static_cast<size_t>(size), std::vector<double>(static_cast<size_t>(raw), 0.0));
  const double step = static_cast<double>(raw) / size;
  for (int p = 0; p < size; ++p) {
    const double u = std::clamp((p + 0.5) * step - 0.5, 0.0, static_cast<double>(raw - 1));
    const int i0 = static_cast<int>(u), i1 = std::min(i0 + 1, raw - 1);
    const double t = u - i0;
    w[p][i0] += 1.0 - t;
    w[p][i1] += t;
  }
  return w;
}

// The summed weights of pixels [lo, hi) along an axis.
std::vector<double> span(const std::vector<std::vector<double>>& w, int lo, int hi) {
  std::vector<double> s(w.empty() ? 0 : w[0].size(), 0.0);
  for (int p = lo; p < hi; ++p)
    for (size_t c = 0; c < s.size(); ++c) s[c] += w[p][c];
  return s;
}

// The lower Cholesky factor of a symmetric positive semidefinite n x n matrix (row-major)
// plus 1e-10 of its largest diagonal on the diagonal: singular matrices (more blocks than
// raw cells along an axis) then factor stably, the band stays, and L L^T is the matrix to
// 1e-10 of its scale (plain Cholesky with zero pivots skipped is not stable there).
std::vector<double> semidefinite_cholesky(const std::vector<double>& a, int n) {
  std::vector<double> l(static_cast<size_t>(n) * n, 0.0);
  double largest = 0;
  for (int i = 0; i < n; ++i) largest = std::max(largest, a[size_t(i) * n + i]);
  const double ridge = 1e-10 * largest;
  for (int k = 0; k < n; ++k) {
    double pivot = a[size_t(k) * n + k] + ridge;
    for (int m = 0; m < k; ++m) pivot -= l[size_t(k) * n + m] * l[size_t(k) * n + m];
    if (!(pivot > 0)) continue;  // an all-zero matrix
    const double root = std::sqrt(pivot);
    l[size_t(k) * n + k] = root;
    for (int i = k + 1; i < n; ++i) {
      double v = a[size_t(i) * n + k];
      for (int m = 0; m < k; ++m) v -= l[size_t(i) * n + m] * l[size_t(k) * n + m];
      l[size_t(i) * n + k] = v / root;
    }
  }
  return l;
}

// Solves L y = b by forward substitution, taking y = 0 where L's pivot is zero.
std::vector<double> forward(const std::vector<double>& l, int n, std::vector<double> b) {
  for (int i = 0; i < n; ++i) {
    for (int m = 0; m < i; ++m) b[i] -= l[size_t(i) * n + m] * b[m];
    b[i] = l[size_t(i) * n + i] > 0 ? b[i] / l[size_t(i) * n + i] : 0.0;
  }
  return b;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t k = 0; k < a.size(); ++k) s += a[k] * b[k];
  return s;
}

// Each block's mean weights along one axis (pixels [b block, (b + 1) block) over raw cells).
std::vector<std::vector<double>> block_axis(const std::vector<std::vector<double>>& w, int size, int block) {
  std::vector<std::vector<double>> m;
  for (int lo = 0; lo < size; lo += block) {
    const int hi = std::min(lo + block, size);
    std::vector<double> v = span(w, lo, hi);
    for (double& x : v) x /= hi - lo;
    m.push_back(std::move(v));
  }
  return m;
}

std::vector<double> gram(const std::vector<std::vector<double>>& m) {
  const size_t n = m.size();
  std::vector<double> g(n * n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) g[i * n + j] = dot(m[i], m[j]);
  return g;
}

int lower_band(const std::vector<double>& l, int n) {
  int band = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j)
      if (l[size_t(i) * n + j] != 0) band = std::max(band, i - j);
  return band;
}

}  // namespace

double RawGridNoise::covariance(const RawGridPooling& p, int f, int g) {
  double c = 0;
  for (int a = p.first[f]; a < p.first[f + 1]; ++a)
    for (int b = p.first[g]; b < p.first[g + 1]; ++b)
      if (p.cells[a] == p.cells[b]) c += p.weights[a] * p.weights[b];
  return c;
}

RawGridNoise raw_grid_noise(const Sensor& s, const FeatureLayout& lay, int raw_width, int raw_height) {
  const std::vector<std::vector<double>> wx = axis_weights(s.width, raw_width), wy = axis_weights(s.height, raw_height);
  const std::vector<std::vector<double>> sx = block_axis(wx, s.width, lay.block),
                                         sy = block_axis(wy, s.height, lay.block);
  RawGridNoise z;
  z.blocks_x = static_cast<int>(sx.size());
  z.blocks_y = static_cast<int>(sy.size());
  const int BX = z.blocks_x, BY = z.blocks_y;
  const std::vector<double> lx = semidefinite_cholesky(gram(sx), BX), ly = semidefinite_cholesky(gram(sy), BY);
  z.band_x = lower_band(lx, BX);
  z.band_y = lower_band(ly, BY);
  const size_t blocks = size_t(BX) * BY;
  z.dx.assign(size_t(z.band_x + 1) * blocks, 0.0);
  z.dy.assign(size_t(z.band_y + 1) * blocks, 0.0);
  for (int by = 0; by < BY; ++by)
    for (int bx = 0; bx < BX; ++bx) {
      const size_t q = size_t(by) * BX + bx;
      for (int d = 0; d <= z.band_x && d <= bx; ++d) z.dx[d * blocks + q] = lx[size_t(bx) * BX + bx - d];
      for (int d = 0; d <= z.band_y && d <= by; ++d) z.dy[d * blocks + q] = ly[size_t(by) * BY + by - d];
    }
  // Regions: qx, qy their mean weights; cov(r, block) = (qy . sy[by]) (qx . sx[bx]), so
  // B's row is (Ly^-1 cy) (x) (Lx^-1 cx).
  std::vector<std::vector<double>> qx, qy, bx_of, by_of;
  for (int r = 0; r < kMaxRegions; ++r) {
    if (!s.sees(r)) continue;
    const Rect& rc = s.rects[r];
    std::vector<double> ax = span(wx, rc.x, rc.x + rc.w), ay = span(wy, rc.y, rc.y + rc.h);
    for (double& v : ax) v /= std::max(rc.w, 1);
    for (double& v : ay) v /= std::max(rc.h, 1);
    std::vector<double> cx(static_cast<size_t>(BX)), cy(static_cast<size_t>(BY));
    for (int b = 0; b < BX; ++b) cx[b] = dot(ax, sx[b]);
    for (int b = 0; b < BY; ++b) cy[b] = dot(ay, sy[b]);
    bx_of.push_back(forward(lx, BX, cx));
    by_of.push_back(forward(ly, BY, cy));
    qx.push_back(std::move(ax));
    qy.push_back(std::move(ay));
  }
  const int R = z.regions = static_cast<int>(qx.size());
  z.region_blocks.assign(size_t(R) * BY * BX, 0.0);
  for (int k = 0; k < R; ++k)
    for (int by = 0; by < BY; ++by)
      for (int bx = 0; bx < BX; ++bx) z.region_blocks[(size_t(k) * BY + by) * BX + bx] = by_of[k][by] * bx_of[k][bx];
  std::vector<double> rest(size_t(R) * R);
  for (int k = 0; k < R; ++k)
    for (int m = 0; m < R; ++m)
      rest[size_t(k) * R + m] =
          dot(qy[k], qy[m]) * dot(qx[k], qx[m]) - dot(by_of[k], by_of[m]) * dot(bx_of[k], bx_of[m]);
  z.region_own = semidefinite_cholesky(rest, R);
  return z;
}

RawGridPooling raw_grid_pooling(const Sensor& s, const FeatureLayout& lay, int slot, int raw_width, int raw_height) {
  const std::vector<std::vector<double>> wx = axis_weights(s.width, raw_width), wy = axis_weights(s.height, raw_height);
  RawGridPooling p;
  // The mean over a rectangle: the outer product of its column and row weights.
  const auto add = [&](int x0, int y0, int x1, int y1, int column) {
    const std::vector<double> sx = span(wx, x0, x1), sy = span(wy, y0, y1);
    const double count = static_cast<double>(x1 - x0) * (y1 - y0);
    p.first.push_back(static_cast<int32_t>(p.cells.size()));
    p.columns.push_back(column);
    for (int j = 0; j < raw_height; ++j)
      for (int i = 0; i < raw_width; ++i)
        if (sy[j] != 0 && sx[i] != 0) {
          p.cells.push_back(j * raw_width + i);
          p.weights.push_back(count > 0 ? sy[j] * sx[i] / count : 0.0);
        }
  };
  const FeatureLayout::Grid& g = lay.grids[slot];
  for (int by = 0; by < g.blocks_y; ++by)
    for (int bx = 0; bx < g.blocks_x; ++bx) {
      const int x0 = bx * lay.block, y0 = by * lay.block;
      add(x0, y0, std::min(x0 + lay.block, s.width), std::min(y0 + lay.block, s.height),
          g.offset + by * g.blocks_x + bx);
    }
  for (int r = 0; r < lay.regions; ++r)
    if (s.sees(r)) {
      const Rect& rc = s.rects[r];
      add(rc.x, rc.y, rc.x + rc.w, rc.y + rc.h, lay.block_features() + r);
    }
  p.first.push_back(static_cast<int32_t>(p.cells.size()));
  return p;
}

}  // namespace portalsim
