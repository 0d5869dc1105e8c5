// The procedural body: its signed distance field, shading and texture, drawn into a view.
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
#include "base/plain_math.h"

namespace portalsim::procedural {

using namespace detail;

namespace {

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

// A row of a view, walked left to right: the body's field is evaluated only where the last
// evaluation left the body within reach (skip_pixels), so the room's pixels cost little.
class RowWalk {
 public:
  RowWalk(const BodyModel& model, double vb, double e, double pu, int width)
      : model_(model), row_(model.row(vb)), e_(e), pu_(pu), width_(width) {}
  // The body's coverage of pixel x (at u), 0 where it is known to be clear; its field in f.
  double coverage_at(int x, double u, BodyField& f) {
    if (x < next_) return 0.0;
    f = model_.eval(u, row_);
    next_ = x + 1 + skip_pixels(f.d - e_, pu_, width_);
    return coverage(f.d, e_);
  }

 private:
  const BodyModel& model_;
  BodyModel::Row row_;
  double e_, pu_;
  int width_;
  int next_ = 0;  // pixels before it are known to be clear of the body
};

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
    RowWalk walk(model, vb, e, pu, width);
    NoiseRow room_noise(v / 9.0, seed + 2);
    FbmRow skin_noise(vb / 22.0, seed + 4);
    for (int x = 0; x < width; ++x) {
      const double u = field_u(field, back, pu, x);
      const double room = bg + 2.0 * room_noise(u / 9.0) + 1.5 * hash_signed(x, y, seed + 3);
      double val = room;
      BodyField f{};
      const double c = walk.coverage_at(x, u, f);
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
    RowWalk walk(model, vb, e, pu, width);
    NoiseRow room_noise(v / 12.0, seed + 6);
    FbmRow skin_noise(vb / 15.0, seed + 7);
    for (int x = 0; x < width; ++x) {
      const double u = field_u(field, back, pu, x);
      const double back = bg + 3.0 * v / 400.0 + 1.5 * room_noise(u / 12.0);
      double val = back;
      BodyField f{};
      const double c = walk.coverage_at(x, u, f);
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

}  // namespace portalsim::procedural
