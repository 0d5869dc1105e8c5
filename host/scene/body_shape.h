// A body's shape: the numbers the procedural body is drawn from (assets/procedural_body.cpp) and
// the vertical map that object places follow (Sensor::subject_dy). One definition, so that
// the drawn body and the places on it cannot drift apart. Units are the portal's field
// (scene/sensor.h): 200 across, the floor 400 below the upper view's top.
#pragma once
#include <cmath>
#include <string_view>

namespace portalsim {

// How the arms are held: down at the sides (the thesis's subjects), raised above the head
// as an imaging portal asks, or held out to the sides.
enum class Pose : int { arms_down = 0, arms_raised = 1, arms_out = 2 };
inline const char* pose_name(Pose p) {
  return p == Pose::arms_raised ? "arms-raised" : (p == Pose::arms_out ? "arms-out" : "arms-down");
}
inline bool parse_pose(std::string_view name, Pose& p) {
  for (Pose q : {Pose::arms_down, Pose::arms_raised, Pose::arms_out})
    if (name == pose_name(q)) {
      p = q;
      return true;
    }
  return false;
}

struct BodyShape {
  double build = 1.0;   // width of torso and legs, 0.5..1.5 (the thesis's builds)
  double height = 1.0;  // stature about the floor, 0.85..1.15 of the 1.75 m body
  // Breadths over the 1.0 body's, where they differ from `build`: 0 means `build`.
  double shoulders = 0.0, chest = 0.0, hips = 0.0;
  // Arm length and crotch height over the 1.0 body's (the rest of the stature is the trunk
  // and head's, so `height` stays the stature).
  double arm_length = 1.0, leg_length = 1.0;
  Pose pose = Pose::arms_down;
  // Whether object places follow the body's width (drawn_col): for drawn bodies and the
  // catalogue's subjects that give a breadth key; not for `build` alone.
  bool places_follow_width = false;

  double shoulders_or_build() const { return shoulders > 0 ? shoulders : build; }
  double chest_or_build() const { return chest > 0 ? chest : build; }
  double hips_or_build() const { return hips > 0 ? hips : build; }
};

// The ranges a catalogue's [[subjects]] keys and the drawn bodies (scene/bodies.h) keep to.
// Stature 0.85..1.15 of 1.75 m is about 1.49 m to 2.01 m: within it the drawn head stays
// inside the upper view and every built-in region's place inside its own view.
struct BodyRange {
  double lo, hi;
};
constexpr BodyRange kBuildRange{0.5, 1.5}, kHeightRange{0.85, 1.15}, kBreadthRange{0.5, 1.5};
constexpr BodyRange kArmLengthRange{0.85, 1.15}, kLegLengthRange{0.9, 1.1};
// Skin at 94 GHz: Owda & Salmon measured reflectivities giving emissivities of about 0.2
// to 0.7 between people; skin surface temperatures of people indoors lie within 300-312 K.
constexpr BodyRange kSkinEmissivityRange{0.1, 0.9}, kSkinTemperatureRange{300.0, 312.0};

// The 1.0 body's floor row, the hip joints' row (where the legs begin) and the top of its
// head, in field rows.
constexpr double kBodyFloorRow = 400.0, kBodyHipRow = 212.0, kBodyTopRow = -66.0;

// The 1.0 body's legs (floor to hip joints) in field rows, and the scale of the rest of the
// stature where the legs scale by `leg_length`: what keeps the stature.
constexpr double kBodyLegRows = kBodyFloorRow - kBodyHipRow;
inline double trunk_scale(const BodyShape& b) {
  return 1.0 + (1.0 - b.leg_length) * kBodyLegRows / (kBodyHipRow - kBodyTopRow);
}

// The row a point of the body at body row `y` (the 1.0 body's) is drawn at: heights above
// the floor scale by `height`, the legs' part of them also by `leg_length` and the rest by
// trunk_scale.
inline double drawn_row(const BodyShape& b, double y) {
  if (b.leg_length == 1.0) return kBodyFloorRow - (kBodyFloorRow - y) * b.height;
  const double c = kBodyFloorRow - y, legs = kBodyLegRows;
  const double drawn = c <= legs ? b.leg_length * c : b.leg_length * legs + trunk_scale(b) * (c - legs);
  return kBodyFloorRow - drawn * b.height;
}

// The body's width scale at body row `y` (the 1.0 body's): the shoulders' above row 45, the
// chest's at row 100, the hips' below row 228, smoothly between (smoothstep); exactly
// `build` where the three are the build. The legs' spacing and thighs follow the hips'.
inline double width_scale(const BodyShape& b, double y) {
  const double sh = b.shoulders_or_build(), ch = b.chest_or_build(), hp = b.hips_or_build();
  if (sh == b.build && ch == b.build && hp == b.build) return b.build;
  const auto step = [](double e0, double e1, double x) {
    double t = (x - e0) / (e1 - e0);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return t * t * (3.0 - 2.0 * t);
  };
  if (y <= 45.0) return sh;
  if (y <= 100.0) return sh + (ch - sh) * step(45.0, 100.0, y);
  if (y < 228.0) return ch + (hp - ch) * step(100.0, 228.0, y);
  return hp;
}

// The column a point of the body at field column `u` and body row `y` is drawn at, for
// object places: scaled about the body's centre line (column 100) by the width at that row
// where places follow the width; `build` alone moves nothing (the thesis placed its objects
// alike on its subjects of every build).
inline double drawn_col(const BodyShape& b, double u, double y) {
  return b.places_follow_width ? 100.0 + (u - 100.0) * width_scale(b, y) : u;
}

// Its inverse: the body row drawn at field row `y`.
inline double body_row(const BodyShape& b, double y) {
  if (b.leg_length == 1.0) return b.height == 1.0 ? y : kBodyFloorRow - (kBodyFloorRow - y) / b.height;
  const double e = (kBodyFloorRow - y) / b.height, legs = kBodyLegRows;
  const double c = e <= b.leg_length * legs ? e / b.leg_length : legs + (e - b.leg_length * legs) / trunk_scale(b);
  return kBodyFloorRow - c;
}

}  // namespace portalsim
