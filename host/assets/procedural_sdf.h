// The procedural images' signed distance primitives (negative inside), and what a row of
// such a field is drawn with. Internal to host/assets/.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "assets/procedural_noise.h"

namespace portalsim::procedural::detail {

// ---- signed distance primitives (negative inside) -------------------------------------

struct P {
  double x, y;
};

inline double len(double x, double y) { return std::sqrt(x * x + y * y); }

inline double sd_circle(P p, P c, double r) { return len(p.x - c.x, p.y - c.y) - r; }

// Scaled-circle approximation: exact sign, 1-Lipschitz, underestimates along the long axis.
inline double sd_ellipse(P p, P c, double rx, double ry) {
  rx = std::max(rx, 1e-3);
  ry = std::max(ry, 1e-3);
  return (len((p.x - c.x) / rx, (p.y - c.y) / ry) - 1.0) * std::min(rx, ry);
}

// Box with centre c, half sizes hx, hy and corner radius r.
inline double sd_box(P p, P c, double hx, double hy, double r) {
  r = std::clamp(r, 0.0, std::min(hx, hy));
  const double qx = std::fabs(p.x - c.x) - hx + r, qy = std::fabs(p.y - c.y) - hy + r;
  return len(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0) - r;
}

// Box given by its edges.
inline double sd_rect(P p, double x0, double y0, double x1, double y1, double r) {
  return sd_box(p, {0.5 * (x0 + x1), 0.5 * (y0 + y1)}, 0.5 * std::fabs(x1 - x0), 0.5 * std::fabs(y1 - y0), r);
}

inline double sd_capsule(P p, P a, P b, double r) {
  const double pax = p.x - a.x, pay = p.y - a.y, bax = b.x - a.x, bay = b.y - a.y;
  const double bb = bax * bax + bay * bay;
  const double h = bb > 0.0 ? clamp01((pax * bax + pay * bay) / bb) : 0.0;
  return len(pax - bax * h, pay - bay * h) - r;
}

// Segment a-b whose radius goes from ra to rb (a tapered capsule, exact). What depends on
// the cone alone is found once, so a body's cones are not set up again at every pixel.
class RoundCone {
 public:
  RoundCone() = default;
  RoundCone(P a, P b, double ra, double rb)
      : a_(a), b_(b), ra_(ra), rb_(rb), bx_(b.x - a.x), by_(b.y - a.y), h_(bx_ * bx_ + by_ * by_), dr_(ra - rb) {
    point_ = h_ <= dr_ * dr_ + 1e-9;
    if (!point_) cx_ = std::sqrt(h_ - dr_ * dr_);
  }
  double operator()(P p) const {
    if (point_) return std::min(sd_circle(p, a_, ra_), sd_circle(p, b_, rb_));
    const double px = p.x - a_.x, py = p.y - a_.y;
    const double qx = std::fabs(px * by_ - py * bx_) / h_, qy = (px * bx_ + py * by_) / h_;
    const double cx = cx_, cy = dr_;
    const double k = cx * qy - cy * qx;
    const double m = cx * qx + cy * qy;
    const double n = qx * qx + qy * qy;
    if (k < 0.0) return std::sqrt(h_ * n) - ra_;
    if (k > cx) return std::sqrt(h_ * (n + 1.0 - 2.0 * qy)) - rb_;
    return m - ra_;
  }

 private:
  P a_{}, b_{};
  double ra_ = 0, rb_ = 0, bx_ = 0, by_ = 0, h_ = 0, dr_ = 0, cx_ = 0;
  bool point_ = true;
};
inline double sd_round_cone(P p, P a, P b, double ra, double rb) { return RoundCone(a, b, ra, rb)(p); }

// Exact distance to a simple polygon.
inline double sd_polygon(P p, const std::vector<P>& v) {
  const size_t n = v.size();
  double d = (p.x - v[0].x) * (p.x - v[0].x) + (p.y - v[0].y) * (p.y - v[0].y);
  double s = 1.0;
  for (size_t i = 0, j = n - 1; i < n; j = i, ++i) {
    const double ex = v[j].x - v[i].x, ey = v[j].y - v[i].y;
    const double wx = p.x - v[i].x, wy = p.y - v[i].y;
    const double ee = ex * ex + ey * ey;
    const double t = ee > 0.0 ? clamp01((wx * ex + wy * ey) / ee) : 0.0;
    const double bx = wx - ex * t, by = wy - ey * t;
    d = std::min(d, bx * bx + by * by);
    const bool c1 = p.y >= v[i].y, c2 = p.y<v[j].y, c3 = ex * wy> ey * wx;
    if ((c1 && c2 && c3) || (!c1 && !c2 && !c3)) s = -s;
  }
  return s * std::sqrt(d);
}

// Polynomial smooth minimum: rounds the joint between two shapes over a width k.
inline double smin(double a, double b, double k) {
  if (k <= 0.0) return std::min(a, b);
  const double h = clamp01(0.5 + 0.5 * (b - a) / k);
  return lerp(b, a, h) - k * h * (1.0 - h);
}

// How many following pixels of a row a 1-Lipschitz field stays above zero for, given its
// margin above the threshold now; lets the outside be skipped without evaluating it.
inline int skip_pixels(double margin, double unit_per_px, int limit) {
  if (!(margin > 0.0)) return 0;
  return static_cast<int>(std::min(margin / unit_per_px, static_cast<double>(limit)));
}

// Edge ramp width in body units: about a pixel and a half, and never razor sharp.
inline double edge_width(double unit_per_px) { return 0.75 * unit_per_px + 0.7; }

inline double coverage(double d, double e) { return smooth(0.5 - d / (2.0 * e)); }

}  // namespace portalsim::procedural::detail
