// The procedural objects: 20 shapes, each a signed distance field with its own shading.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "assets/procedural.h"
#include "assets/procedural_noise.h"
#include "assets/procedural_sdf.h"

namespace portalsim::procedural {

using namespace detail;

namespace {

// ---- sprites ----------------------------------------------------------------------------

// A shape in the horizontal frame: a W x H box in pixels, y down.
class Shape {
 public:
  Shape(double w, double h) : w_(w), h_(h), m_(std::min(w, h)) {}
  virtual ~Shape() = default;
  virtual double sd(P p) const = 0;
  // Offset from the material level at a point inside.
  virtual double shade(P p) const = 0;

 protected:
  P at(double u, double v) const { return {u * w_, v * h_}; }
  // Gentle darkening over the outer rim, so every object reads as having volume.
  double rim(double d, double width, double amount) const {
    const double t = clamp01(-d / std::max(width, 0.5));
    return -amount * (1.0 - t) * (1.0 - t);
  }
  double grain(P p, uint64_t seed) const {
    return hash_signed(static_cast<int64_t>(std::floor(p.x)), static_cast<int64_t>(std::floor(p.y)), seed);
  }
  double w_, h_, m_;
};

// Cylinder shading across a coordinate c in [-1, 1]: dark edges and a bright band.
double cylinder(double c, double band_at, double band_width) {
  const double body = 8.0 - 30.0 * c * c;
  const double t = std::max(0.0, 1.0 - ((c - band_at) / band_width) * ((c - band_at) / band_width));
  return body + 28.0 * t * t;
}

class Gun : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double slide = sd_rect(p, 0.07 * w_, 0.04 * h_, 0.95 * w_, 0.31 * h_, 0.05 * m_);
    const double muzzle = sd_rect(p, 0.90 * w_, 0.10 * h_, 1.0 * w_, 0.24 * h_, 0.02 * m_);
    const double frame = sd_rect(p, 0.10 * w_, 0.28 * h_, 0.80 * w_, 0.41 * h_, 0.03 * m_);
    // The grip rakes back about 18 degrees, as on most pistols.
    const double grip = sd_polygon(p, {at(0.08, 0.36), at(0.38, 0.36), at(0.27, 0.99), at(0.03, 0.96)}) - 0.01 * m_;
    const double hammer = sd_rect(p, 0.02 * w_, 0.03 * h_, 0.12 * w_, 0.17 * h_, 0.03 * m_);
    const double t = std::max(1.0, 0.06 * m_);
    const P gc = at(0.50, 0.40);
    const double outer = sd_ellipse(p, gc, 0.15 * w_, 0.24 * h_);
    const double inner = sd_ellipse(p, gc, 0.15 * w_ - t, 0.24 * h_ - t);
    const double guard = std::max({outer, -inner, gc.y - p.y});
    const double trigger = sd_capsule(p, at(0.49, 0.40), at(0.46, 0.55), std::max(0.45, 0.03 * m_));
    return std::min({slide, muzzle, frame, grip, hammer, guard, trigger});
  }
  double shade(P p) const override {
    const double u = p.x / w_, v = p.y / h_;
    double s = rim(sd(p), 0.06 * m_ + 0.8, 16.0);
    if (v < 0.31 && u > 0.07) {  // slide: brighter, highlight along the top, port, serrations
      s += 10.0 + 18.0 * std::max(0.0, 1.0 - std::fabs(v - 0.10) / 0.05);
      if (u > 0.52 && u < 0.68 && v > 0.12 && v < 0.21) s -= 26.0;
      if (u > 0.12 && u < 0.25) s -= 10.0 * wave(p.x / std::max(1.6, 0.05 * w_));
      if (u > 0.90) s -= 8.0;
    } else if (v > 0.40 && u < 0.40) {  // grip: darker, checkered panel
      const double panel = sd_polygon(p, {at(0.14, 0.45), at(0.32, 0.45), at(0.23, 0.92), at(0.07, 0.91)});
      s -= 12.0;
      if (panel < 0.0) s -= 8.0 + 7.0 * wave((p.x + p.y) / 2.2) * wave((p.x - p.y) / 2.2);
    } else {
      s -= 2.0;
    }
    return s + 2.0 * grain(p, 11);
  }
};

class Handle : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double bar = sd_rect(p, 0, 0, w_, 0.36 * h_, 0.18 * h_);
    const double post_l = sd_rect(p, 0.15 * w_, 0.2 * h_, 0.27 * w_, 0.88 * h_, 0.02 * m_);
    const double post_r = sd_rect(p, 0.73 * w_, 0.2 * h_, 0.85 * w_, 0.88 * h_, 0.02 * m_);
    const double base_l = sd_rect(p, 0.08 * w_, 0.80 * h_, 0.34 * w_, h_, 0.06 * m_);
    const double base_r = sd_rect(p, 0.66 * w_, 0.80 * h_, 0.92 * w_, h_, 0.06 * m_);
    return std::min({bar, post_l, post_r, base_l, base_r});
  }
  double shade(P p) const override {
    const double u = p.x / w_, v = p.y / h_;
    double s;
    if (v < 0.36) {
      s = cylinder((v - 0.18) / 0.18, -0.35, 0.35);
    } else if (v < 0.80) {
      const double cx = u < 0.5 ? 0.21 : 0.79;
      s = cylinder((u - cx) / 0.06, -0.3, 0.4) - 6.0;
    } else {
      s = -14.0 + 10.0 * std::max(0.0, 1.0 - std::fabs(v - 0.86) / 0.06);
    }
    return s + rim(sd(p), 0.6, 8.0) + 1.5 * grain(p, 12);
  }
};

// Long thin shapes (rod, strip, pipe) follow the box's long axis.
class Elongated : public Shape {
 public:
  using Shape::Shape;

 protected:
  bool horizontal() const { return w_ >= h_; }
  double along(P p) const { return horizontal() ? p.x / w_ : p.y / h_; }
  double across(P p) const {  // -1..1 over the thickness
    return horizontal() ? (p.y - 0.5 * h_) / (0.5 * h_) : (p.x - 0.5 * w_) / (0.5 * w_);
  }
  double length() const { return std::max(w_, h_); }
};

class Rod : public Elongated {
 public:
  using Elongated::Elongated;
  // Inset a little across its thickness so the long sides get a soft, anti-aliased edge.
  double sd(P p) const override {
    const double ix = horizontal() ? 0.0 : 0.05 * w_, iy = horizontal() ? 0.05 * h_ : 0.0;
    return sd_rect(p, ix, iy, w_ - ix, h_ - iy, 0.45 * m_);
  }
  double shade(P p) const override {
    return cylinder(across(p), -0.35, 0.32) + rim(sd(p), 0.8, 6.0) +
           3.0 * value_noise(along(p) * length() / 5.0, 0.5, 21);
  }
};

class Strip : public Elongated {
 public:
  using Elongated::Elongated;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, 0.5 * m_); }
  double shade(P p) const override {
    const double c = across(p);
    // Flat: nearly even, a thin sheen along one edge and a faint ripple along the length.
    double s =
        4.0 - 10.0 * smoothstep(0.55, 1.0, c) + 12.0 * smoothstep(-0.95, -0.6, -c) * smoothstep(-0.95, -0.6, c + 0.3);
    s += 5.0 * (along(p) - 0.5) + 3.0 * value_noise(along(p) * length() / 7.0, 3.5, 22);
    return s + rim(sd(p), 0.7, 8.0);
  }
};

class Disk : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const P c = at(0.5, 0.5);
    const double outer = sd_ellipse(p, c, 0.5 * w_, 0.5 * h_);
    const double hole = sd_ellipse(p, c, 0.15 * w_, 0.15 * h_);
    return std::max(outer, -hole);
  }
  double shade(P p) const override {
    const double dx = (p.x - 0.5 * w_) / (0.5 * w_), dy = (p.y - 0.5 * h_) / (0.5 * h_);
    const double r2 = dx * dx + dy * dy, r = std::sqrt(r2);
    double s;
    if (r < 0.36) {  // clear plastic hub with a stacking ring
      s = -14.0 + 10.0 * std::max(0.0, 1.0 - std::fabs(r - 0.25) / 0.04);
    } else {  // data area: fine tracks and a two-lobed sheen
      const double sin2 = r2 > 0.0 ? 2.0 * dx * dy / r2 : 0.0;
      s = 6.0 + 4.0 * wave(r * 0.5 * m_ / 1.5) + 20.0 * sin2 * sin2 - 8.0;
      if (r > 0.94) s += 8.0;
    }
    return s + rim(sd(p), 0.7, 10.0);
  }
};

class Plate : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, 0.09 * m_); }
  double shade(P p) const override {
    const double d = sd(p);
    const double bw = std::max(1.2, 0.09 * m_);
    double s = 2.0 * value_noise(p.x / 9.0, p.y / 1.5, 31);  // brushed grain
    if (-d < bw) {                                           // bevel lit from the top left
      const double e = 0.25;
      const double gx = sd({p.x + e, p.y}) - sd({p.x - e, p.y});
      const double gy = sd({p.x, p.y + e}) - sd({p.x, p.y - e});
      const double g = len(gx, gy);
      const double lit = g > 0.0 ? -(gx + gy) / g * 0.7071 : 0.0;
      s += 18.0 * lit * (1.0 - (-d) / bw);
    }
    const double inset = std::max(2.0, 0.16 * m_), rr = std::max(0.8, 0.06 * m_);
    for (const P& c : {P{inset, inset}, P{w_ - inset, inset}, P{inset, h_ - inset}, P{w_ - inset, h_ - inset}}) {
      const double dc = sd_circle(p, c, rr);
      if (dc < 0.0)
        s += 18.0 * (1.0 + dc / rr) - 4.0;
      else if (dc < 0.8)
        s -= 12.0 * (1.0 - dc / 0.8);
    }
    return s + rim(d, 0.6, 6.0);
  }
};

class Pendant : public Shape {
 public:
  Pendant(double w, double h) : Shape(w, h) {
    big_r_ = std::max(0.5, std::min(0.42 * w_, 0.27 * h_));
    centre_ = {0.5 * w_, h_ - big_r_ - 0.02 * h_};
    loop_c_ = at(0.5, 0.16);
    loop_rx_ = 0.28 * w_;
    loop_ry_ = 0.155 * h_;
    loop_t_ = std::max(0.9, 0.1 * w_);
  }
  double sd(P p) const override {
    const double outer = sd_ellipse(p, loop_c_, loop_rx_, loop_ry_);
    const double inner = sd_ellipse(p, loop_c_, loop_rx_ - loop_t_, loop_ry_ - loop_t_);
    const double loop = std::max(outer, -inner);
    const double drop = sd_round_cone(p, centre_, at(0.5, 0.30), big_r_, std::max(0.5, 0.08 * w_));
    return std::min(loop, drop);
  }
  double shade(P p) const override {
    if (p.y < 0.30 * h_) {  // chain: bright beads
      const double dx = p.x - loop_c_.x, dy = p.y - loop_c_.y;
      const double a = dy / (std::fabs(dx) + std::fabs(dy) + 1e-9) + (dx < 0 ? 4.0 : 0.0);
      return 6.0 + 16.0 * wave(a * 2.2) - 12.0;
    }
    const double dc = sd_circle(p, centre_, big_r_);
    const double rim_w = std::max(0.8, 0.2 * big_r_);
    double s = 2.0;
    if (-dc < rim_w) s += 14.0;  // raised rim
    const double gem = sd_circle(p, centre_, 0.42 * big_r_);
    if (gem < 0.0) s += 24.0 * (-gem / (0.42 * big_r_)) - 6.0;  // domed centre stone
    s -= 10.0 * clamp01((p.x - centre_.x + p.y - centre_.y) / (2.0 * big_r_));
    return s + rim(sd(p), 0.6, 8.0);
  }

 private:
  double big_r_;
  P centre_, loop_c_;
  double loop_rx_, loop_ry_, loop_t_;
};

class Pipe : public Elongated {
 public:
  using Elongated::Elongated;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, 0.12 * m_); }
  double shade(P p) const override {
    double s = cylinder(across(p), -0.4, 0.22) + 4.0;
    // Fitting collars near both ends.
    const double a = along(p) * length(), cw = std::max(1.0, 0.08 * m_);
    for (double x : {0.09 * length(), 0.91 * length()})
      if (std::fabs(a - x) < cw) s -= 16.0 * (1.0 - std::fabs(a - x) / cw);
    if (a < 0.04 * length() || a > 0.96 * length()) s += 6.0;
    return s + rim(sd(p), 0.7, 6.0) + 2.0 * grain(p, 41);
  }
};

class Buckle : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double outer = sd_rect(p, 0, 0, w_, h_, 0.2 * m_);
    const double hole = sd_rect(p, 0.24 * w_, 0.22 * h_, 0.84 * w_, 0.78 * h_, 0.06 * m_);
    const double frame = std::max(outer, -hole);
    const double prong =
        sd_round_cone(p, at(0.12, 0.5), at(0.90, 0.5), std::max(0.6, 0.07 * h_), std::max(0.4, 0.03 * h_));
    return std::min(frame, prong);
  }
  double shade(P p) const override {
    const double outer = sd_rect(p, 0, 0, w_, h_, 0.2 * m_);
    const double hole = sd_rect(p, 0.24 * w_, 0.22 * h_, 0.84 * w_, 0.78 * h_, 0.06 * m_);
    const double frame = std::max(outer, -hole);
    if (frame > 0.0 || std::fabs(p.y - 0.5 * h_) < 0.05 * h_) {  // prong
      if (hole < 0.0) return 14.0 - 10.0 * clamp01(std::fabs(p.y - 0.5 * h_) / (0.06 * h_));
    }
    // Frame bars look rounded: bright along their middle, dark at both edges.
    const double half = 0.5 * std::min(0.24 * w_, 0.25 * h_);
    const double c = clamp01(-frame / std::max(half, 0.5));
    return cylinder(1.0 - c, -0.1, 0.5) + 2.0 * grain(p, 51);
  }
};

class Tile : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, std::max(0.5, 0.05 * m_)); }
  double shade(P p) const override {
    const double d = sd(p);
    double s = 4.0 * value_noise(p.x / 5.0, p.y / 5.0, 61) + 5.0 * grain(p, 62);
    s += 6.0 * (1.0 - (p.x + p.y) / (w_ + h_));  // glaze catching light from the top left
    const double gw = std::max(1.0, 0.08 * m_);
    if (-d < gw) s -= 14.0 + 6.0 * grain(p, 63);  // grout left on the edges
    return s;
  }
};

class Slab : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, 0.3 * m_); }
  double shade(P p) const override {
    const double sc = std::max(3.0, 0.22 * m_);
    double s = 14.0 * fbm(p.x / sc, p.y / sc, 71) + 6.0 * grain(p, 72);
    if (hash01(static_cast<int64_t>(std::floor(p.x / 2.0)), static_cast<int64_t>(std::floor(p.y / 2.0)), 73) > 0.96)
      s -= 18.0;  // pores
    return s + rim(sd(p), std::max(1.0, 0.1 * m_), 14.0);
  }
};

class Phone : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double body = sd_rect(p, 0, 0, 0.93 * w_, h_, 0.17 * std::min(0.93 * w_, h_));
    const double b1 = sd_rect(p, 0.9 * w_, 0.22 * h_, w_, 0.29 * h_, 0.02 * m_);
    const double b2 = sd_rect(p, 0.9 * w_, 0.34 * h_, w_, 0.48 * h_, 0.02 * m_);
    return std::min({body, b1, b2});
  }
  double shade(P p) const override {
    const double u = p.x / w_;
    if (u > 0.93) return -8.0;  // side buttons
    const double screen = sd_rect(p, 0.09 * w_, 0.11 * h_, 0.84 * w_, 0.84 * h_, 0.02 * m_);
    if (screen < 0.0) {
      // Glass: darker, with a diagonal reflection.
      const double k = (p.x / w_ + p.y / h_) * 2.2;
      return -24.0 + 10.0 * std::max(0.0, 1.0 - std::fabs(k - 1.0) / 0.25) + rim(screen, 0.8, 6.0);
    }
    double s = 6.0 + rim(sd(p), std::max(0.8, 0.06 * m_), 16.0);
    if (sd_capsule(p, at(0.34, 0.055), at(0.58, 0.055), std::max(0.4, 0.012 * h_)) < 0.0) s -= 28.0;  // earpiece
    if (sd_circle(p, at(0.22, 0.055), std::max(0.4, 0.02 * h_)) < 0.0) s -= 24.0;                     // camera
    const double button = sd_circle(p, at(0.465, 0.92), std::max(0.6, 0.045 * h_));
    if (std::fabs(button) < std::max(0.45, 0.012 * h_)) s -= 20.0;
    return s;
  }
};

// A knife lying blade right, edge down: a rounded handle with two rivets, a bolster, and a
// blade whose spine runs straight to a drop point while the edge sweeps up to it.
class Knife : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double handle = sd_rect(p, 0.0, 0.20 * h_, 0.40 * w_, 0.84 * h_, 0.30 * h_);
    const double bolster = sd_rect(p, 0.38 * w_, 0.10 * h_, 0.44 * w_, 0.94 * h_, 0.05 * m_);
    const double blade =
        sd_polygon(p, {at(0.43, 0.06), at(0.84, 0.06), at(1.0, 0.32), at(0.91, 0.66), at(0.72, 0.90), at(0.43, 0.95)});
    return std::min({handle, bolster, blade});
  }
  double shade(P p) const override {
    const double u = p.x / w_, v = p.y / h_;
    double s;
    if (u < 0.38) {  // handle: darker scales, two bright rivets
      s = -16.0 + 4.0 * value_noise(p.x / 3.0, p.y / 3.0, 81);
      for (double ru : {0.10, 0.28})
        if (sd_circle(p, at(ru, 0.52), std::max(0.5, 0.12 * h_)) < 0.0) s += 26.0;
    } else if (u < 0.44) {  // bolster
      s = 10.0;
    } else {  // blade: bright flat, the edge's grind a darker band, a sheen along the spine
      s = 6.0 + 14.0 * std::max(0.0, 1.0 - std::fabs(v - 0.16) / 0.12);
      if (v > 0.68 - 0.3 * clamp01((u - 0.7) / 0.3)) s -= 10.0;
    }
    return s + rim(sd(p), 0.6, 8.0) + 1.5 * grain(p, 82);
  }
};

// A bunch of keys: a split ring on the left and three keys fanning out from it.
class Keys : public Shape {
 public:
  Keys(double w, double h) : Shape(w, h) {
    ring_ = at(0.16, 0.50);
    ring_r_ = std::max(1.0, 0.26 * h_);
    for (int k = 0; k < 3; ++k) {
      head_[k] = at(0.40, 0.24 + 0.26 * k);
      tip_[k] = at(0.97, 0.12 + 0.38 * k);
    }
  }
  double sd(P p) const override {
    const double t = std::max(0.45, 0.07 * h_);
    double d = std::fabs(sd_circle(p, ring_, ring_r_)) - t;
    for (int k = 0; k < 3; ++k) {
      d = std::min(d, sd_circle(p, head_[k], std::max(0.8, 0.17 * h_)));
      d = std::min(d, sd_capsule(p, head_[k], tip_[k], std::max(0.5, 0.07 * h_)));
    }
    return d;
  }
  double shade(P p) const override {
    double s = 6.0;
    for (int k = 0; k < 3; ++k)
      if (sd_circle(p, head_[k], std::max(0.8, 0.17 * h_)) < 0.0) s = 12.0 - 6.0 * k;  // heads of three metals
    return s + rim(sd(p), 0.5, 10.0) + 2.0 * grain(p, 91);
  }

 private:
  P ring_, head_[3], tip_[3];
  double ring_r_;
};

// A few coins, overlapping: raised rims and a relief in each face.
class Coins : public Shape {
 public:
  Coins(double w, double h) : Shape(w, h) {
    r_ = 0.30 * m_;
    c_[0] = at(0.30, 0.36);
    c_[1] = at(0.68, 0.40);
    c_[2] = at(0.46, 0.68);
  }
  double sd(P p) const override {
    return std::min({sd_circle(p, c_[0], r_), sd_circle(p, c_[1], r_), sd_circle(p, c_[2], r_)});
  }
  double shade(P p) const override {
    for (int k = 2; k >= 0; --k) {  // the last coin lies on top
      const double d = sd_circle(p, c_[k], r_);
      if (d < 0.0) {
        double s = 4.0 * k - 4.0 + 10.0 * value_noise(p.x / 1.5, p.y / 1.5, 101 + k);
        if (-d < std::max(0.5, 0.15 * r_)) s += 14.0;  // rim
        return s;
      }
    }
    return 0.0;
  }

 private:
  P c_[3];
  double r_;
};

// A folded wallet: a rounded leather case with the fold down its middle, stitching along
// its edge and the bulge of cards.
class Wallet : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, 0.12 * m_); }
  double shade(P p) const override {
    const double d = sd(p), u = p.x / w_;
    double s = 6.0 * fbm(p.x / 2.5, p.y / 2.5, 111) + 2.0 * grain(p, 112);  // grain of the leather
    if (std::fabs(u - 0.5) < 0.03) s -= 14.0;                               // the fold
    const double inset = std::max(1.0, 0.1 * m_);
    if (std::fabs(-d - inset) < 0.35 && wave((p.x + p.y) / 1.6) > 0.5) s -= 10.0;  // stitching
    s += 8.0 * std::max(0.0, 1.0 - std::fabs(p.y / h_ - 0.45) / 0.3) * (u > 0.55 ? 1.0 : 0.0);
    return s + rim(d, 0.8, 10.0);
  }
};

// A wristwatch as it lies, strap straight: a round case with a crown, a bracelet of links.
class Watch : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double strap = sd_rect(p, 0, 0.22 * h_, w_, 0.78 * h_, 0.2 * h_);
    const double c = sd_circle(p, at(0.5, 0.5), 0.5 * h_);
    const double crown = sd_rect(p, 0.46 * w_, 0.0, 0.54 * w_, 0.08 * h_, 0.02 * m_);
    return std::min({strap, c, crown});
  }
  double shade(P p) const override {
    const double dc = sd_circle(p, at(0.5, 0.5), 0.5 * h_);
    if (dc < 0.0) {
      if (-dc < std::max(0.6, 0.14 * h_)) return 16.0 + rim(dc, 0.5, 8.0);                            // the bezel
      return -18.0 + 8.0 * std::max(0.0, 1.0 - std::fabs(p.x - p.y - 0.5 * (w_ - h_)) / (0.2 * h_));  // the glass
    }
    return 4.0 + 10.0 * wave(p.x / std::max(1.2, 0.12 * h_)) + rim(sd(p), 0.5, 8.0);  // links
  }
};

// Folded glasses: two lenses in thin frames joined by a bridge, the temples folded across
// their tops.
class Glasses : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override {
    const double l = sd_ellipse(p, at(0.26, 0.56), 0.22 * w_, 0.40 * h_);
    const double r = sd_ellipse(p, at(0.74, 0.56), 0.22 * w_, 0.40 * h_);
    const double bridge = sd_capsule(p, at(0.46, 0.38), at(0.54, 0.38), std::max(0.45, 0.06 * h_));
    const double temples = sd_capsule(p, at(0.03, 0.14), at(0.97, 0.14), std::max(0.45, 0.06 * h_));
    return std::min({l, r, bridge, temples});
  }
  double shade(P p) const override {
    const double l = sd_ellipse(p, at(0.26, 0.56), 0.22 * w_, 0.40 * h_);
    const double r = sd_ellipse(p, at(0.74, 0.56), 0.22 * w_, 0.40 * h_);
    const double lens = std::min(l, r), frame = std::max(0.5, 0.09 * h_);
    if (lens < 0.0 && -lens > frame) return -12.0 + 10.0 * std::max(0.0, 1.0 - std::fabs(p.x / w_ - p.y / h_) / 0.15);
    return 14.0 + 2.0 * grain(p, 121);  // the frame, the bridge and the temples
  }
};

// A drinks bottle lying down: the body, a shoulder, the neck and a ribbed cap on the right.
class Bottle : public Elongated {
 public:
  using Elongated::Elongated;
  double sd(P p) const override {
    const P q = horizontal() ? p : P{p.y, p.x};  // along the box's long side
    const double L = length(), T = horizontal() ? h_ : w_;
    const double body = sd_rect(q, 0, 0, 0.70 * L, T, 0.25 * T);
    const double shoulder = sd_round_cone(q, {0.66 * L, 0.5 * T}, {0.86 * L, 0.5 * T}, 0.46 * T, 0.16 * T);
    const double cap = sd_rect(q, 0.86 * L, 0.30 * T, L, 0.70 * T, 0.05 * T);
    return std::min({body, shoulder, cap});
  }
  double shade(P p) const override {
    const double a = along(p);
    double s = cylinder(across(p), -0.3, 0.3);
    if (a > 0.18 && a < 0.52) s -= 8.0;                                                 // the label
    if (a > 0.86) s = 6.0 + 8.0 * wave(a * length() / std::max(1.0, 0.05 * length()));  // the cap's ribs
    return s + rim(sd(p), 0.6, 6.0);
  }
};

// A flat sheet in a wrapper: low relief, the wrapper's creases, a band of tape across it.
class Sheet : public Shape {
 public:
  using Shape::Shape;
  double sd(P p) const override { return sd_rect(p, 0, 0, w_, h_, std::max(0.5, 0.06 * m_)); }
  double shade(P p) const override {
    double s = 5.0 * fbm(p.x / 6.0, p.y / 3.0, 131) + 2.0 * grain(p, 132);
    s -= 8.0 * std::max(0.0, 1.0 - std::fabs(p.x - 0.6 * p.y - 0.3 * w_) / 1.2);  // a crease
    if (std::fabs(p.x / w_ - 0.5) < 0.08) s += 10.0;                              // tape
    return s + rim(sd(p), 0.6, 6.0);
  }
};

// Shading offset squeezed smoothly into the room between the level and 0 or 255, so bright
// metals keep their highlights instead of clipping flat.
double fit_shade(double s, double level) {
  s = std::clamp(s, -40.0, 40.0);
  const double room = s > 0.0 ? 255.0 - level : level;
  if (room <= 0.0) return 0.0;
  return s * room / (room + std::fabs(s));
}

std::unique_ptr<Shape> make_shape(const std::string& name, double w, double h) {
  if (name == "gun") return std::make_unique<Gun>(w, h);
  if (name == "handle") return std::make_unique<Handle>(w, h);
  if (name == "rod") return std::make_unique<Rod>(w, h);
  if (name == "disk") return std::make_unique<Disk>(w, h);
  if (name == "strip") return std::make_unique<Strip>(w, h);
  if (name == "plate") return std::make_unique<Plate>(w, h);
  if (name == "pendant") return std::make_unique<Pendant>(w, h);
  if (name == "pipe") return std::make_unique<Pipe>(w, h);
  if (name == "buckle") return std::make_unique<Buckle>(w, h);
  if (name == "tile") return std::make_unique<Tile>(w, h);
  if (name == "slab") return std::make_unique<Slab>(w, h);
  if (name == "phone") return std::make_unique<Phone>(w, h);
  if (name == "knife") return std::make_unique<Knife>(w, h);
  if (name == "keys") return std::make_unique<Keys>(w, h);
  if (name == "coins") return std::make_unique<Coins>(w, h);
  if (name == "wallet") return std::make_unique<Wallet>(w, h);
  if (name == "watch") return std::make_unique<Watch>(w, h);
  if (name == "glasses") return std::make_unique<Glasses>(w, h);
  if (name == "bottle") return std::make_unique<Bottle>(w, h);
  if (name == "sheet") return std::make_unique<Sheet>(w, h);
  return nullptr;
}

}  // namespace

Image sprite(const std::string& shape, bool vertical, int width, int height, int level) {
  check_size(width, height, "sprite");
  // The drawing lives in the horizontal frame; a vertical sprite is it turned clockwise.
  const int hw = vertical ? height : width, hh = vertical ? width : height;
  const auto s = make_shape(shape, hw, hh);
  if (!s) throw std::invalid_argument("sprite: unknown shape '" + shape + "'");
  const double lv = std::clamp(level, 0, 255);
  Image img(width, height, 2);
  for (int y = 0; y < height; ++y) {
    int next = 0;  // pixels before `next` are known to be outside
    for (int x = 0; x < width; ++x) {
      double value = lv, alpha = 0.0;
      if (x < next) {
        img.at(x, y, 0) = to_u8(value);
        continue;
      }
      // Horizontal-frame pixel this output pixel shows.
      const int hx = vertical ? y : x, hy = vertical ? hh - 1 - x : y;
      const P centre{hx + 0.5, hy + 0.5};
      const double dc = s->sd(centre);
      next = x + 1 + skip_pixels(dc - 2.0, 1.0, width);
      if (dc < -2.0) {
        value = lv + fit_shade(s->shade(centre), lv);
        alpha = 255.0;
      } else if (dc <= 2.0) {
        // 4x4 supersampled coverage; the value averages the covered samples.
        int inside = 0;
        double sum = 0.0;
        for (int j = 0; j < 4; ++j) {
          for (int i = 0; i < 4; ++i) {
            const P q{hx + (i + 0.5) / 4.0, hy + (j + 0.5) / 4.0};
            if (s->sd(q) < 0.0) {
              ++inside;
              sum += fit_shade(s->shade(q), lv);
            }
          }
        }
        if (inside > 0) value = lv + sum / inside;
        alpha = 255.0 * inside / 16.0;
      }
      img.at(x, y, 0) = to_u8(value);
      img.at(x, y, 1) = to_u8(alpha);
    }
  }
  return img;
}

}  // namespace portalsim::procedural
