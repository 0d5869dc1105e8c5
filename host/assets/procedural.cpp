// Procedural default images. Geometry is signed distance fields (negative inside) built
// from a handful of primitives; texture comes from an integer hash, so the bytes depend
// only on IEEE arithmetic (+, *, /, sqrt, floor), never on libm or a platform RNG: the
// pose's and the folds' sines are base/plain_math.h's, made of those operations alone.
#include "assets/procedural.h"

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

#include "base/plain_math.h"

namespace portalsim::procedural {
namespace {

// Refuse absurd sizes with an exception rather than an allocation failure deep inside.
constexpr int64_t kMaxPixels = int64_t{1} << 28;

// Added to a body's texture seeds where it is seen from the back.
constexpr uint64_t kBackSeed = 0x6261636bull;  // "back"

// Column x's centre in the field, pu field units a pixel: a back view sees the field
// mirrored, its left edge the field's right.
double field_u(const Frame& field, bool back, double pu, int x) {
  return back ? field.x + field.w - (x + 0.5) * pu : (x + 0.5) * pu + field.x;
}

void check_size(int w, int h, const char* what) {
  if (w < 1 || h < 1) throw std::invalid_argument(std::string(what) + ": width and height must be at least 1");
  if (static_cast<int64_t>(w) * h > kMaxPixels) throw std::invalid_argument(std::string(what) + ": image too large");
}

// ---- hashing and texture -------------------------------------------------------------

uint64_t mix64(uint64_t z) {  // splitmix64 finaliser
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// One finaliser over a lattice-scrambled key: cheap, and no visible pattern for texture.
uint64_t hash3(int64_t x, int64_t y, uint64_t seed) {
  const uint64_t k = static_cast<uint64_t>(x) * 0xd1b54a32d192ed03ULL ^
                     static_cast<uint64_t>(y) * 0xabc98388fb8fac03ULL ^ seed * 0x8cb92ba72f3d8dd7ULL;
  return mix64(k ^ (k >> 29));
}

// Uniform in [0, 1) and [-1, 1).
double hash01(int64_t x, int64_t y, uint64_t seed) {
  return static_cast<double>(hash3(x, y, seed) >> 11) * (1.0 / 9007199254740992.0);
}
double hash_signed(int64_t x, int64_t y, uint64_t seed) { return 2.0 * hash01(x, y, seed) - 1.0; }

double clamp01(double t) { return t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t); }
double smooth(double t) {
  t = clamp01(t);
  return t * t * (3.0 - 2.0 * t);
}
double smoothstep(double e0, double e1, double x) { return smooth((x - e0) / (e1 - e0)); }
double lerp(double a, double b, double t) { return a + (b - a) * t; }

// Bilinear value noise with a smooth fade, in [-1, 1], along one row (y fixed): the lattice
// row and its fade once, a cell's four corner hashes once while x stays in the cell (the body
// views draw whole rows of it).
class NoiseRow {
 public:
  NoiseRow(double y, uint64_t seed) : seed_(seed) {
    const double fy = std::floor(y);
    iy_ = static_cast<int64_t>(fy);
    ty_ = smooth(y - fy);
  }
  double operator()(double x) {
    const double fx = std::floor(x);
    const auto ix = static_cast<int64_t>(fx);
    if (!cached_ || ix != ix_) {
      a_ = hash_signed(ix, iy_, seed_), b_ = hash_signed(ix + 1, iy_, seed_);
      c_ = hash_signed(ix, iy_ + 1, seed_), d_ = hash_signed(ix + 1, iy_ + 1, seed_);
      ix_ = ix;
      cached_ = true;
    }
    const double tx = smooth(x - fx);
    return lerp(lerp(a_, b_, tx), lerp(c_, d_, tx), ty_);
  }

 private:
  uint64_t seed_;
  int64_t iy_ = 0, ix_ = 0;
  double ty_ = 0, a_ = 0, b_ = 0, c_ = 0, d_ = 0;
  bool cached_ = false;
};
double value_noise(double x, double y, uint64_t seed) { return NoiseRow(y, seed)(x); }

// Two octaves, still roughly in [-1, 1]; and along one row.
class FbmRow {
 public:
  FbmRow(double y, uint64_t seed) : first_(y, seed), second_(2.03 * y - 5.3, seed + 1) {}
  double operator()(double x) { return 0.67 * first_(x) + 0.33 * second_(2.03 * x + 17.1); }

 private:
  NoiseRow first_, second_;
};
double fbm(double x, double y, uint64_t seed) { return FbmRow(y, seed)(x); }

// Triangle wave in [0, 1] with period 1, smoothed to a cosine-like shape (1 at integers).
double wave(double t) {
  const double f = t - std::floor(t);
  return smooth(std::fabs(2.0 * f - 1.0));
}

uint8_t to_u8(double v) {
  if (!(v > 0.0)) return 0;  // also maps NaN to 0
  if (v >= 255.0) return 255;
  return static_cast<uint8_t>(std::floor(v + 0.5));
}

// ---- signed distance primitives (negative inside) -------------------------------------

struct P {
  double x, y;
};

double len(double x, double y) { return std::sqrt(x * x + y * y); }

double sd_circle(P p, P c, double r) { return len(p.x - c.x, p.y - c.y) - r; }

// Scaled-circle approximation: exact sign, 1-Lipschitz, underestimates along the long axis.
double sd_ellipse(P p, P c, double rx, double ry) {
  rx = std::max(rx, 1e-3);
  ry = std::max(ry, 1e-3);
  return (len((p.x - c.x) / rx, (p.y - c.y) / ry) - 1.0) * std::min(rx, ry);
}

// Box with centre c, half sizes hx, hy and corner radius r.
double sd_box(P p, P c, double hx, double hy, double r) {
  r = std::clamp(r, 0.0, std::min(hx, hy));
  const double qx = std::fabs(p.x - c.x) - hx + r, qy = std::fabs(p.y - c.y) - hy + r;
  return len(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0) - r;
}

// Box given by its edges.
double sd_rect(P p, double x0, double y0, double x1, double y1, double r) {
  return sd_box(p, {0.5 * (x0 + x1), 0.5 * (y0 + y1)}, 0.5 * std::fabs(x1 - x0), 0.5 * std::fabs(y1 - y0), r);
}

double sd_capsule(P p, P a, P b, double r) {
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
double sd_round_cone(P p, P a, P b, double ra, double rb) { return RoundCone(a, b, ra, rb)(p); }

// Exact distance to a simple polygon.
double sd_polygon(P p, const std::vector<P>& v) {
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
double smin(double a, double b, double k) {
  if (k <= 0.0) return std::min(a, b);
  const double h = clamp01(0.5 + 0.5 * (b - a) / k);
  return lerp(b, a, h) - k * h * (1.0 - h);
}

// ---- the body --------------------------------------------------------------------------

// The whole body in one frame: U across (0..200), Y down, 0..200 the upper MMW view and
// 200..400 the lower one, so the IR view is the same field at half scale.
struct BodyField {
  double d;       // union
  double d_core;  // torso, shoulders, pelvis
  double d_head;  // neck and chin
  double d_arm;
  double d_leg;
  double chin;  // 0..1 crease darkening along the jaw line
};

class BodyModel {
 public:
  explicit BodyModel(const Body& body) {
    const auto scale = [](double v, double lo, double hi) { return std::isfinite(v) ? std::clamp(v, lo, hi) : 1.0; };
    shape_ = body.shape;
    shape_.build = scale(shape_.build, 0.5, 1.6);
    shape_.height = scale(shape_.height, 0.5, 2.0);
    shape_.leg_length = scale(shape_.leg_length, 0.5, 1.5);
    shape_.shoulders = scale(shape_.shoulders_or_build(), 0.5, 1.6);
    shape_.chest = scale(shape_.chest_or_build(), 0.5, 1.6);
    shape_.hips = scale(shape_.hips_or_build(), 0.5, 1.6);
    arm_len_ = scale(shape_.arm_length, 0.5, 1.5);
    // The arms' turn outwards about the shoulder, from hanging down: held out nearly level,
    // or raised above the head.
    const double turn = shape_.pose == Pose::arms_out ? 75.0 : (shape_.pose == Pose::arms_raised ? 160.0 : 0.0);
    const plain::SinCos arm = plain::sincos(turn * 3.14159265358979323846 / 180.0);
    arm_cos_ = arm.cos, arm_sin_ = arm.sin;
    seed_ = mix64(static_cast<uint64_t>(static_cast<int64_t>(body.subject)) + 0x5eed);
    auto var = [&](int k) { return hash01(k, 0, seed_); };
    arm_spread_ = 4.0 * var(1);
    shoulder_dy_ = 4.0 * var(2) - 2.0;
    stance_ = 3.0 * var(3);
    lean_ = 3.0 * var(4) - 1.5;
    arm_off_ = 64.5 + (shape_.shoulders - 1.0) * 52.0;
    arms_[0] = arm_of(-1.0), arms_[1] = arm_of(1.0);
    legs_[0] = leg_of(-1.0), legs_[1] = leg_of(1.0);
    // The trapezius slopes' cones (eval joins them to the core).
    const double tx = arm_off_ - 9.0;
    trap_[0] = RoundCone({100, 13}, {100 - tx, 33 + shoulder_dy_}, 13, 10);
    trap_[1] = RoundCone({100, 13}, {100 + tx, 33 + shoulder_dy_}, 13, 10);
  }

  uint64_t seed() const { return seed_; }

  // The body's own row drawn at image row y of the whole-body frame (0..400, floor at 400):
  // the stature and the legs scaled about the floor (scene/body_shape.h). Exactly y at
  // height 1 and leg length 1.
  double body_row(double y) const { return portalsim::body_row(shape_, y); }

  // What eval needs of body row y that does not change along the row.
  struct Row {
    double y;
    double centre, half_width;  // the torso's centre and half width
  };
  Row row(double y) const { return {y, centre_x(y), torso_half_width(y) * width_scale(y)}; }

  BodyField eval(double u, const Row& row) const {
    const double y = row.y;
    BodyField f{};
    const double far = 1e9;
    const double sdy = shoulder_dy_;
    // Head: neck and the underside of the chin, only near the top.
    double head = far;
    double jaw = far, neck = far;
    if (y < 60.0) {
      neck = neck_({u, y});
      jaw = jaw_({u, y});
      head = smin(neck, jaw, 2.0);
    }
    // Core: shoulder girdle, trapezius slopes, torso and pelvis.
    double core = torso(u, row);
    if (y < 80.0) {
      // Trapezius slopes from the neck down to round deltoids.
      const double trap = std::min(trap_[0]({u, y}), trap_[1]({u, y}));
      core = smin(core, trap, 6.0);
    }
    double arm = far;
    if (y < 215.0) {
      // Arms keep |u - 100| >= arm_off_ - 12, so deep inside the torso they cannot change
      // the union or the IR weights (both ignore a part 14 units further than the nearest).
      const double bound = arm_off_ - 12.0 - std::fabs(u - 100.0);
      arm = bound >= core + 14.0 ? bound
                                 : nearer(arms_[0], arms_[1], {u, y}, [&](int k) { return limb_arm(u, y, arms_[k]); });
    }
    if (y < 80.0) {  // shoulders round over into the deltoids
      const double delt = std::min(sd_circle({u, y}, {100 - arm_off_, 43 + sdy}, 10.5),
                                   sd_circle({u, y}, {100 + arm_off_, 43 + sdy}, 10.5));
      core = smin(core, delt, 8.0);
    }
    double leg = far;
    if (y > 180.0) leg = nearer(legs_[0], legs_[1], {u, y}, [&](int k) { return limb_leg(u, y, legs_[k]); });
    f.d_core = core;
    f.d_head = head;
    f.d_arm = arm;
    f.d_leg = leg;
    core = smin(core, leg, 5.0);  // the hips flow into the thighs
    f.d = smin(smin(core, head, 6.0), arm, 2.5);
    // The jaw line shows as a soft dark crease where the chin overhangs the neck.
    if (y < 60.0 && neck < 0.0) f.chin = std::max(0.0, 1.0 - std::fabs(jaw) / 2.5);
    return f;
  }

 private:
  // Torso half width along Y (before build), a smooth curve through key points.
  static double torso_half_width(double y) {
    static constexpr double kY[] = {18, 30, 45, 70, 100, 125, 160, 200, 228, 245, 262, 280};
    static constexpr double kW[] = {36, 50, 53, 51.5, 47.5, 45.5, 48.5, 53.5, 55, 53.5, 48, 40};
    constexpr int n = sizeof(kY) / sizeof(kY[0]);
    if (y <= kY[0]) return kW[0];
    if (y >= kY[n - 1]) return kW[n - 1];
    int i = 0;
    while (y > kY[i + 1]) ++i;
    auto slope = [&](int k) {
      const int a = std::max(k - 1, 0), b = std::min(k + 1, n - 1);
      return (kW[b] - kW[a]) / (kY[b] - kY[a]);
    };
    const double dx = kY[i + 1] - kY[i], t = (y - kY[i]) / dx;
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * kW[i] + (t3 - 2 * t2 + t) * dx * slope(i) + (-2 * t3 + 3 * t2) * kW[i + 1] +
           (t3 - t2) * dx * slope(i + 1);
  }

  double centre_x(double y) const { return 100.0 + lean_ * smoothstep(150.0, 300.0, y); }

  // The width scale at row y (scene/body_shape.h, the one definition object places follow).
  double width_scale(double y) const { return portalsim::width_scale(shape_, y); }

  double torso(double u, const Row& row) const {
    const double side = std::fabs(u - row.centre) - row.half_width;
    return std::max({side, 18.0 - row.y, row.y - 262.0});
  }

  // A limb's round cones, joined with smin: joint k to joint k + 1, radius r[k] to r[k + 1]
  // (a leg's foot: joints 5 to 6). Its joints depend on the body only, so they are found once.
  struct Limb {
    Limb() = default;
    // Joints and radii (the rest zero), the smins' most, and the two boxes: joints 0..split
    // and split..last.
    Limb(std::initializer_list<P> joints, std::initializer_list<double> radii, double smin_slack, int split, int last)
        : slack(smin_slack) {
      if (joints.size() > 7 || radii.size() != joints.size())
        throw std::logic_error("Limb: up to 7 joints, a radius each");
      std::copy(joints.begin(), joints.end(), j);
      std::copy(radii.begin(), radii.end(), r);
      bound(0, 0, split);
      bound(1, split, last);
      for (int k = 0; k < 6; ++k) cones[k] = RoundCone(j[k], j[k + 1], r[k], r[k + 1]);
    }
    P j[7]{};
    double r[7]{};
    // Two boxes of joints and each's largest radius: the limb's distance is at least the
    // nearer box's distance less its radius, less the smins' most (their widths / 4).
    double box[2][4]{}, box_r[2]{}, slack = 0;
    // At most what the limb's distance can be at p (see box): where the other limb's value
    // is already below it, the min is the other's, bit for bit.
    double floor(P p) const {
      double d = 1e300;
      for (int b = 0; b < 2; ++b) {
        const double dx = std::max({box[b][0] - p.x, 0.0, p.x - box[b][1]});
        const double dy = std::max({box[b][2] - p.y, 0.0, p.y - box[b][3]});
        d = std::min(d, len(dx, dy) - box_r[b]);
      }
      return d - slack - 1e-6;  // the margin covers the cones' rounding
    }
    void bound(int b, int from, int to) {
      box[b][0] = box[b][2] = 1e300, box[b][1] = box[b][3] = -1e300, box_r[b] = 0;
      for (int k = from; k <= to; ++k) {
        box[b][0] = std::min(box[b][0], j[k].x), box[b][1] = std::max(box[b][1], j[k].x);
        box[b][2] = std::min(box[b][2], j[k].y), box[b][3] = std::max(box[b][3], j[k].y);
        box_r[b] = std::max(box_r[b], r[k]);
      }
    }
    RoundCone cones[6];  // joint k to k + 1
    double cone(P p, int k) const { return cones[k](p); }
  };

  // sgn -1: the subject's right arm, on the image's left. Joints top, elbow, wrist, hand.
  Limb arm_of(double sgn) const {
    const double x0 = 100.0 + sgn * arm_off_;
    const P top{x0, 43 + shoulder_dy_};
    // A joint at (out, down) from the shoulder's top in the hanging arm, stretched by the
    // arm's length and turned outwards by the pose (exactly the old points hanging at 1).
    const auto joint = [&](double out, double y) {
      const double dx = sgn * out * arm_len_, dy = (y - top.y) * arm_len_;
      if (shape_.pose == Pose::arms_down) return P{x0 + dx, y + (arm_len_ - 1.0) * (y - top.y)};
      return P{top.x + dx * arm_cos_ + sgn * dy * arm_sin_, top.y - sgn * dx * arm_sin_ + dy * arm_cos_};
    };
    return Limb(
        {top, joint(2.5 + 0.4 * arm_spread_, 113), joint(5.0 + arm_spread_, 171), joint(6.0 + 1.1 * arm_spread_, 186)},
        {10.5, 8.2, 6.3, 7.2}, (1.5 + 1.5) / 4, 1, 3);
  }
  double limb_arm(double u, double y, const Limb& a) const {
    const P p{u, y};
    return smin(smin(a.cone(p, 0), a.cone(p, 1), 1.5), a.cone(p, 2), 1.5);
  }

  // Joints hip, mid, knee, calf, ankle, then the foot's two ends: seen from the front, low,
  // wider than the ankle, turned a little outwards.
  Limb leg_of(double sgn) const {
    const double bl = 0.5 + 0.5 * shape_.build, hp = shape_.hips;
    const double x0 = 100.0 + lean_ + sgn * (26.5 * hp + 0.3 * stance_);
    const double ankle = x0 + sgn * (0.5 + 0.5 * stance_);
    return Limb({{x0, 212},
                 {x0 + sgn * 0.3, 270},
                 {x0 + sgn * (1.0 + 0.5 * stance_), 310},
                 {x0 + sgn * (1.6 + 0.7 * stance_), 333},
                 {ankle, 382},
                 {ankle + sgn * 0.5, 389},
                 {ankle + sgn * 5.5, 393}},
                {26.0 * hp, 24.0 * hp, 14.5 * bl, 16.5 * bl, 7.8 * bl, 7.5 * bl, 5.0 * bl}, (3.0 + 2.5 + 2.0 + 4.0) / 4,
                2, 6);
  }
  double limb_leg(double u, double y, const Limb& l) const {
    const P p{u, y};
    const double thigh = smin(l.cone(p, 0), l.cone(p, 1), 3.0);
    const double shin = smin(l.cone(p, 2), l.cone(p, 3), 2.5);
    return smin(smin(thigh, shin, 2.0), l.cone(p, 5), 4.0);
  }

  // min(limb 0, limb 1), the right's first as std::min takes them; the limb whose floor is
  // above the other's value is not evaluated (it cannot be the min).
  template <class Eval>
  static double nearer(const Limb& a, const Limb& b, P p, const Eval& eval) {
    const double fa = a.floor(p), fb = b.floor(p);
    if (fa <= fb) {
      const double va = eval(0);
      return fb >= va ? va : std::min(va, eval(1));
    }
    const double vb = eval(1);
    return fa >= vb ? vb : std::min(eval(0), vb);
  }

  BodyShape shape_;  // the body's shape, build, breadths, stature and legs clamped
  double arm_len_ = 1.0, arm_cos_ = 1.0, arm_sin_ = 0.0;
  uint64_t seed_ = 0;
  double arm_spread_ = 0, shoulder_dy_ = 0, stance_ = 0, lean_ = 0, arm_off_ = 64.5;
  Limb arms_[2]{}, legs_[2]{};  // the subject's right, then left
  RoundCone trap_[2];           // the trapezius slopes, right then left
  RoundCone neck_{{100, -6}, {100, 17}, 11.5, 13.0}, jaw_{{100, -36}, {100, -10}, 30.0, 19.0};
};

// How many following pixels of a row a 1-Lipschitz field stays above zero for, given its
// margin above the threshold now; lets the outside be skipped without evaluating it.
int skip_pixels(double margin, double unit_per_px, int limit) {
  if (!(margin > 0.0)) return 0;
  return static_cast<int>(std::min(margin / unit_per_px, static_cast<double>(limit)));
}

// Edge ramp width in body units: about a pixel and a half, and never razor sharp.
double edge_width(double unit_per_px) { return 0.75 * unit_per_px + 0.7; }

double coverage(double d, double e) { return smooth(0.5 - d / (2.0 * e)); }

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

// ---- palette ------------------------------------------------------------------------------

struct Stop {
  int at;
  int r, g, b;
};
constexpr Stop kIron[] = {{0, 0, 0, 0},       {36, 22, 0, 92},    {78, 92, 0, 150},    {118, 168, 6, 140},
                          {152, 218, 38, 64}, {186, 246, 108, 0}, {222, 255, 196, 24}, {255, 255, 252, 236}};
constexpr Stop kGray[] = {{0, 0, 0, 0}, {255, 255, 255, 255}};  // white hot
// Rainbow: blue (cold), cyan, green, yellow, red, white (hot).
constexpr Stop kRainbow[] = {{0, 0, 0, 128},     {40, 0, 0, 255},   {92, 0, 224, 255},   {140, 0, 224, 0},
                             {184, 255, 240, 0}, {228, 255, 32, 0}, {255, 255, 255, 255}};

}  // namespace

Image mmw_body(const Body& body, bool upper, int width, int height) {
  return mmw_view(body, upper ? Frame{0, 0, 200, 200} : Frame{0, 200, 200, 200}, Side::front, width, height);
}

Image ir_body(const Body& body, int width, int height) { return ir_view(body, Frame{}, Side::front, width, height); }

Image mmw_view(const Body& body, const Frame& field, Side side, int width, int height) {
  check_size(width, height, "mmw_body");
  const BodyModel model(body);
  Image img(width, height, 1);
  const double pu = field.w / width, pv = field.h / height;
  const double e = edge_width(std::max(pu, pv));
  const double level = body.mmw_level, bg = body.mmw_background;
  const bool back = side == Side::back;
  // The back's own texture (its seeds apart from the front's), and no chin.
  const uint64_t seed = model.seed() + (back ? kBackSeed : 0);
  const double chin = back ? 0.0 : 18.0;
  for (int y = 0; y < height; ++y) {
    const double v = (y + 0.5) * pv + field.y;
    const double vb = model.body_row(v);  // the body drawn here; the room stays at v
    const BodyModel::Row row = model.row(vb);
    NoiseRow room_noise(v / 9.0, seed + 2);
    FbmRow skin_noise(vb / 22.0, seed + 4);
    int next = 0;  // pixels before `next` are known to be clear of the body
    for (int x = 0; x < width; ++x) {
      const double u = field_u(field, back, pu, x);
      const double room = bg + 2.0 * room_noise(u / 9.0) + 1.5 * hash_signed(x, y, seed + 3);
      double val = room;
      if (x < next) {
        img.at(x, y) = to_u8(val);
        continue;
      }
      const BodyField f = model.eval(u, row);
      next = x + 1 + skip_pixels(f.d - e, pu, width);
      const double c = coverage(f.d, e);
      if (c > 0.0) {
        const double depth = clamp01(-f.d / 26.0);
        const double s = 1.0 - (1.0 - depth) * (1.0 - depth);
        const double skin = level + 34.0 * (s - 0.7) + 4.0 * skin_noise(u / 22.0) + 2.5 * hash_signed(x, y, seed + 5) -
                            chin * f.chin * f.chin;
        val = lerp(room, skin, c);
      }
      img.at(x, y) = to_u8(val);
    }
  }
  return img;
}

Image ir_view(const Body& body, const Frame& field, Side side, int width, int height) {
  check_size(width, height, "ir_body");
  const BodyModel model(body);
  Image img(width, height, 1);
  const double pu = field.w / width, pv = field.h / height;
  const double e = edge_width(std::max(pu, pv));
  const double core = body.ir_core, limb = body.ir_limb, bg = body.ir_background;
  const bool back = side == Side::back;
  const uint64_t seed = model.seed() + (back ? kBackSeed : 0);
  for (int y = 0; y < height; ++y) {
    const double v = (y + 0.5) * pv + field.y;
    const double vb = model.body_row(v);  // the body drawn here; the room stays at v
    const BodyModel::Row row = model.row(vb);
    NoiseRow room_noise(v / 12.0, seed + 6);
    FbmRow skin_noise(vb / 15.0, seed + 7);
    int next = 0;
    for (int x = 0; x < width; ++x) {
      const double u = field_u(field, back, pu, x);
      const double back = bg + 3.0 * v / 400.0 + 1.5 * room_noise(u / 12.0);
      double val = back;
      if (x < next) {
        img.at(x, y) = to_u8(val);
        continue;
      }
      const BodyField f = model.eval(u, row);
      next = x + 1 + skip_pixels(f.d - e, pu, width);
      const double c = coverage(f.d, e);
      if (c > 0.0) {
        // Each part's own temperature, blended by how close the point is to each part.
        const double sa = clamp01((vb - 45.0) / 147.0), sl = clamp01((vb - 240.0) / 158.0);
        const double t_core = core - 8.0 * (1.0 - clamp01(-f.d_core / 20.0));
        const double t_head = limb + 0.55 * (core - limb);
        const double t_arm = limb + 0.4 * (core - limb) * (1.0 - sa) * (1.0 - sa) - 26.0 * sa * sa;
        const double t_leg = limb + 0.55 * (core - limb) * (1.0 - sl) * (1.0 - sl) - 30.0 * sl * sl;
        // Trunk and legs are one piece: a gradient down from the hips, not a seam.
        const double t_trunk = lerp(t_core, t_leg, smoothstep(225.0, 320.0, vb));
        const double d_trunk = std::min(f.d_core, f.d_leg);
        const double dm = std::min({d_trunk, f.d_head, f.d_arm});
        auto weight = [&](double d) { return smooth(1.0 - (d - dm) / 14.0); };
        const double wc = weight(d_trunk), wh = weight(f.d_head), wa = weight(f.d_arm);
        double t = (wc * t_trunk + wh * t_head + wa * t_arm) / (wc + wh + wa);
        const double depth = clamp01(-f.d / 9.0);
        t -= 16.0 * (1.0 - depth) * (1.0 - depth);  // the surface turns away at the edges
        t += 1.5 * skin_noise(u / 15.0);
        val = lerp(back, t, c);
      }
      img.at(x, y) = to_u8(val);
    }
  }
  return img;
}

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

Image fold_pattern(const Image& base, const Sensor& view, int body_lo, int body_hi, int texture) {
  check_size(base.width, base.height, "fold pattern");
  Image out(base.width, base.height, 1, 0);
  const uint64_t seed = 0xf01d5ULL + static_cast<uint64_t>(texture);
  const double phase = 2.0 * std::numbers::pi * hash01(texture, 1, seed);
  const double per_col = std::abs(view.field_per_col());
  constexpr double kCreaseEvery = 22.0, kCreaseWidth = 0.3;  // field units; its share of the period
  constexpr double kSeamIn = 3.0, kSeamWidth = 1.5, kCentreWidth = 2.0, kCentreFrom = 40.0;
  // Crease k lies across the body near v = 22 k, bent with a wavelength, height and phase of
  // its own, and of its own depth along it: per crease and column, its bend and depth.
  const double v0 = view.field_row(0.5), v1 = view.field_row(base.height - 0.5);
  const int64_t k0 = static_cast<int64_t>(std::floor(std::min(v0, v1) / kCreaseEvery)) - 1;
  const int64_t k1 = static_cast<int64_t>(std::floor(std::max(v0, v1) / kCreaseEvery)) + 1;
  const size_t W = static_cast<size_t>(base.width);
  std::vector<double> bend(static_cast<size_t>(k1 - k0 + 1) * W), depth(bend.size());
  for (int64_t k = k0; k <= k1; ++k) {
    const auto own = [&](int j) { return hash01(k, j, seed); };
    const double height = 2.0 + 3.0 * own(3), wave = 25.0 + 20.0 * own(4), shift = own(5);
    const double deep = 0.35 + 0.65 * own(2), stretch = 40.0 + 30.0 * own(6), at = own(7);
    for (size_t x = 0; x < W; ++x) {
      const double u = view.field_col(static_cast<double>(x) + 0.5);
      const size_t i = static_cast<size_t>(k - k0) * W + x;
      bend[i] = height * plain::sin(2.0 * std::numbers::pi * (u / wave + shift) + phase);
      depth[i] = deep * (0.5 + 0.5 * plain::sin(2.0 * std::numbers::pi * (u / stretch + at)));
    }
  }
  for (int y = 0; y < base.height; ++y) {
    const double v = view.field_row(y + 0.5);
    const int64_t near = static_cast<int64_t>(std::floor(v / kCreaseEvery));
    for (int a = 0; a < base.width;) {
      const auto body = [&](int x) { return base.at(x, y) >= body_lo && base.at(x, y) <= body_hi; };
      if (!body(a)) {
        ++a;
        continue;
      }
      int b = a;
      while (b < base.width && body(b)) ++b;
      const double run = (b - a) * per_col, centre = 0.5 * (a + b);
      for (int x = a; x < b; ++x) {
        // A crease's profile across it: (4 t (1 - t))^2 over t in [0, 1) of its width.
        double m = 0;
        for (int64_t k = near - 1; k <= near + 1; ++k) {
          const size_t i = static_cast<size_t>(k - k0) * W + static_cast<size_t>(x);
          const double t = ((v + bend[i]) / kCreaseEvery - static_cast<double>(k)) / kCreaseWidth;
          if (t < 0 || t >= 1) continue;
          const double bump = 4.0 * t * (1.0 - t);
          m = std::max(m, depth[i] * bump * bump);
        }
        const double in = std::min(x - a, b - 1 - x) * per_col + 0.5 * per_col;
        if (run >= 4 * kSeamIn && in >= kSeamIn && in < kSeamIn + kSeamWidth) m = 1;
        if (run >= kCentreFrom && std::abs(x + 0.5 - centre) * per_col < kCentreWidth / 2) m = 1;
        out.at(x, y) = static_cast<uint8_t>(std::lround(255.0 * clamp01(m)));
      }
      a = b;
    }
  }
  return out;
}

Image noise_pattern(int k, int size) {
  if (k < 0 || k >= kProceduralNoisePatterns)
    throw std::invalid_argument("noise_pattern: k must be in 0.." + std::to_string(kProceduralNoisePatterns - 1));
  check_size(size, size, "noise_pattern");
  Image img(size, size, 1, 128);
  if (size < 3) return img;  // all border
  const uint64_t seed = 0x6e6f697365ULL + static_cast<uint64_t>(k);
  const double n = size, half = 0.5 * (size - 1);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      // Envelope: flat in the middle, smoothly to exactly 0 on the border pixels.
      const double ex = std::fabs(x - half) / half, ey = std::fabs(y - half) / half;
      const double env = smoothstep(0.0, 0.45, 1.0 - ex) * smoothstep(0.0, 0.45, 1.0 - ey);
      if (env <= 0.0) continue;
      double a = 0.0;
      switch (k) {
        case 0:  // fine speckle: independent pixels, a few strong ones
        {
          const double h = hash_signed(x, y, seed);
          a = h * std::fabs(h) * 0.6 + 0.4 * h;
          break;
        }
        case 1:  // horizontal streaks: long along x, a few pixels across
          a = 0.95 * value_noise(x / std::max(6.0, n / 4.0), y / 2.2, seed) + 0.12 * hash_signed(x, y, seed + 1);
          break;
        case 2: {  // low-frequency blotches, contrast-stretched
          const double b = fbm(x / std::max(3.0, n / 5.0), y / std::max(3.0, n / 5.0), seed);
          a = std::clamp(1.8 * b, -1.0, 1.0);
          break;
        }
        case 3: {  // concentric rings, slightly wobbly
          const double dx = x - half, dy = y - half;
          const double r = len(dx, dy) + 1.2 * value_noise(x / 8.0, y / 8.0, seed);
          a = 2.0 * wave(r / std::max(3.0, n / 10.0)) - 1.0;
          break;
        }
        default:  // vertical banding: columns of varying brightness
          a = 0.75 * value_noise(x / 2.5, y / std::max(8.0, n / 3.0), seed) +
              0.25 * value_noise(x / 7.0, 0.5, seed + 1);
          a = std::clamp(1.4 * a, -1.0, 1.0);
          break;
      }
      img.at(x, y) = to_u8(128.0 + 45.0 * env * std::clamp(a, -1.0, 1.0));
    }
  }
  return img;
}

const char* palette_name(PaletteName p) {
  return p == PaletteName::gray ? "gray" : p == PaletteName::rainbow ? "rainbow" : "ironbow";
}

std::array<std::array<uint8_t, 3>, 256> ir_palette(PaletteName which) {
  const std::span<const Stop> stops = which == PaletteName::gray      ? std::span<const Stop>(kGray)
                                      : which == PaletteName::rainbow ? std::span<const Stop>(kRainbow)
                                                                      : std::span<const Stop>(kIron);
  std::array<std::array<uint8_t, 3>, 256> pal{};
  const size_t n = stops.size();
  for (int i = 0; i < 256; ++i) {
    size_t k = 0;
    while (k + 2 < n && i > stops[k + 1].at) ++k;
    const Stop& a = stops[k];
    const Stop& b = stops[k + 1];
    const double t = static_cast<double>(i - a.at) / (b.at - a.at);
    pal[i] = {to_u8(lerp(a.r, b.r, t)), to_u8(lerp(a.g, b.g, t)), to_u8(lerp(a.b, b.b, t))};
  }
  return pal;
}

}  // namespace portalsim::procedural
