#include "scene/bodies.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "base/plain_math.h"
#include "scene/philox.h"

namespace portalsim {

namespace {

// Means and standard deviations (mm) of the US Army's 2012 anthropometric survey, ANSUR II
// (Gordon et al., NATICK/TR-15/007, 2014), computed from its public files: 4082 men and
// 1986 women. Stature, biacromial (shoulder), chest and hip breadth, with their correlations;
// crotch height and arm length (acromion-radiale + radiale-stylion + hand length) as
// fractions of stature.
struct Survey {
  std::array<double, 4> mean, sd;  // stature, shoulders, chest, hips
  // Correlations: stature-shoulders, stature-chest, stature-hips, shoulders-chest,
  // shoulders-hips, chest-hips.
  std::array<double, 6> r;
  struct {
    double mean, sd;
  } crotch, arm;
};
constexpr Survey kMen{{1756.2, 415.7, 289.4, 345.7},
                      {68.6, 19.2, 18.3, 24.2},
                      {0.53, 0.34, 0.38, 0.58, 0.47, 0.62},
                      {0.4815, 0.0141},
                      {0.4535, 0.0121}};
constexpr Survey kWomen{{1628.5, 365.3, 269.3, 353.8},
                        {64.2, 18.3, 18.6, 26.7},
                        {0.57, 0.35, 0.39, 0.43, 0.30, 0.58},
                        {0.4802, 0.0151},
                        {0.4504, 0.0135}};
// The 1.0 body: 1.75 m tall ([metal.physics] body_height), its breadths and limb fractions
// the two sexes' mean means, so that men and women sit either side of it.
constexpr double kUnitStature = 1750.0;
constexpr std::array<double, 3> kUnitBreadths{(kMen.mean[1] + kWomen.mean[1]) / 2, (kMen.mean[2] + kWomen.mean[2]) / 2,
                                              (kMen.mean[3] + kWomen.mean[3]) / 2};
constexpr double kUnitCrotch = (kMen.crotch.mean + kWomen.crotch.mean) / 2,
                 kUnitArm = (kMen.arm.mean + kWomen.arm.mean) / 2;
// Skin at 80-100 GHz reflects 0.61 +- 0.09 (Owda & Salmon, SPIE 2020): emissivity 0.39 +-
// 0.09 between people, kept within the 0.2-0.7 they report.
constexpr double kSkinEmissivitySd = 0.09, kSkinEmissivityLo = 0.2, kSkinEmissivityHi = 0.7;
// Assumed: the mean skin temperature of resting people indoors spreads by about 1 K between
// people; kept within 2.5 K of the catalogue's, where the IR images' index range holds it.
constexpr double kSkinTemperatureSd = 1.0, kSkinTemperatureSpan = 2.5;

// Two standard normals from two 32-bit words (Box-Muller; u1 in (0, 1]).
std::array<double, 2> normals(uint32_t a, uint32_t b) {
  const double u1 = 1.0 - uniform24(a), u2 = uniform24(b);
  const double radius = std::sqrt(-2.0 * plain::log(u1)), angle = 2.0 * 3.14159265358979323846 * u2;
  const plain::SinCos sc = plain::sincos(angle);
  return {radius * sc.cos, radius * sc.sin};
}

// z independent standard normals -> correlated ones with the survey's correlations
// (Cholesky factor of the 4x4 matrix, computed here from its six entries).
std::array<double, 4> correlate(const Survey& s, const std::array<double, 4>& z) {
  double c[4][4] = {{1, s.r[0], s.r[1], s.r[2]},
                    {s.r[0], 1, s.r[3], s.r[4]},
                    {s.r[1], s.r[3], 1, s.r[5]},
                    {s.r[2], s.r[4], s.r[5], 1}};
  double l[4][4] = {};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j <= i; ++j) {
      double sum = c[i][j];
      for (int k = 0; k < j; ++k) sum -= l[i][k] * l[j][k];
      l[i][j] = i == j ? std::sqrt(sum) : sum / l[j][j];
    }
  std::array<double, 4> out{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j <= i; ++j) out[i] += l[i][j] * z[j];
  return out;
}

double within(double v, BodyRange r) { return std::clamp(v, r.lo, r.hi); }

}  // namespace

Subject draw_body(const Catalogue& cat, uint64_t seed, uint64_t k, DrawnBody* drawn) {
  const auto word = [&](uint32_t element) { return draw(seed, k, kStreamBodies, element); };
  const Philox4 w0 = word(0), w1 = word(1), w2 = word(2);
  DrawnBody d;
  d.female = (w0[0] >> 31) != 0;
  const Survey& s = d.female ? kWomen : kMen;
  const auto n01 = normals(w1[0], w1[1]), n23 = normals(w1[2], w1[3]), n45 = normals(w2[0], w2[1]),
             n67 = normals(w2[2], w2[3]);
  const std::array<double, 4> z = correlate(s, {n01[0], n01[1], n23[0], n23[1]});
  d.stature_mm = s.mean[0] + s.sd[0] * z[0];
  d.shoulders_mm = s.mean[1] + s.sd[1] * z[1];
  d.chest_mm = s.mean[2] + s.sd[2] * z[2];
  d.hips_mm = s.mean[3] + s.sd[3] * z[3];
  d.crotch_ratio = s.crotch.mean + s.crotch.sd * n45[0];
  d.arm_ratio = s.arm.mean + s.arm.sd * n45[1];

  Subject b;
  char name[32];
  std::snprintf(name, sizeof name, "body-%03llu", static_cast<unsigned long long>(k) + 1);
  b.name = name;
  BodyShape& shape = b.shape;
  shape.height = within(d.stature_mm / kUnitStature, kHeightRange);
  shape.shoulders = within(d.shoulders_mm / kUnitBreadths[0], kBreadthRange);
  shape.chest = within(d.chest_mm / kUnitBreadths[1], kBreadthRange);
  shape.hips = within(d.hips_mm / kUnitBreadths[2], kBreadthRange);
  shape.build = within((shape.shoulders + shape.chest + shape.hips) / 3.0, kBuildRange);
  shape.places_follow_width = true;
  shape.leg_length = within(d.crotch_ratio / kUnitCrotch, kLegLengthRange);
  shape.arm_length = within(d.arm_ratio / kUnitArm, kArmLengthRange);
  // Assumed: the three poses equally often (walk-through portals see arms down, imaging
  // portals ask for arms raised; people also hold them out).
  shape.pose = static_cast<Pose>(below(w0[1], 3));
  b.texture = static_cast<int64_t>(w0[2] >> 1);

  const PhysicsConfig& pc = cat.physics;
  b.skin_emissivity = std::clamp(pc.skin_emissivity + kSkinEmissivitySd * n67[0], kSkinEmissivityLo, kSkinEmissivityHi);
  b.skin_temperature =
      std::clamp(pc.skin_temperature + kSkinTemperatureSd * n67[1], pc.skin_temperature - kSkinTemperatureSpan,
                 pc.skin_temperature + kSkinTemperatureSpan);
  // The images' levels follow the skin: MMW gray scales with the bare body's apparent
  // temperature above the room (150 at the catalogue's skin, as subject-1), the IR index
  // moves with the skin's kelvin on the catalogue's index map.
  const Subject unit;
  const auto seen = [&](double e, double t) { return pc.seen_through_clothing(e, t, pc.room_temperature); };
  const double g0 = pc.base_background_gray, room = pc.background_temperature;
  const double level = g0 + (unit.mmw_level - g0) * (seen(b.skin_emissivity, b.skin_temperature) - room) /
                                (seen(pc.skin_emissivity, pc.skin_temperature) - room);
  b.mmw_level = std::clamp(static_cast<int>(std::lround(level)), 0, 255);
  if (b.mmw_level == pc.base_background_gray) b.mmw_level += 1;  // the physics model reads it as kelvin
  const double per_kelvin = 255.0 / (pc.ir_index_max_k - pc.ir_index_min_k);
  const double shift = (b.skin_temperature - pc.skin_temperature) * per_kelvin;
  b.ir_core = std::clamp(static_cast<int>(std::lround(unit.ir_core + shift)), 0, 255);
  b.ir_limb = std::clamp(static_cast<int>(std::lround(unit.ir_limb + shift)), 0, 255);
  // Assumed: the body itself reads nothing on the metal detector; the thesis's five measured
  // subjects read 198-200 of 200.
  b.base_zones.assign(static_cast<size_t>(cat.zones), 200);
  char row[256];
  std::snprintf(row, sizeof row, "%s,%.1f,%.1f,%.1f,%.1f,%.4f,%.4f,%s,%.3f,%.2f,%lld", d.female ? "female" : "male",
                d.stature_mm, d.shoulders_mm, d.chest_mm, d.hips_mm, d.crotch_ratio, d.arm_ratio, pose_name(shape.pose),
                b.skin_emissivity, b.skin_temperature, static_cast<long long>(b.texture));
  b.drawn = row;
  if (drawn) *drawn = d;
  return b;
}

std::string body_summary(const Subject& s) {
  if (s.drawn.empty()) return "";
  // The record's fields: sex, stature_mm, ..., pose (kBodyColumns).
  std::vector<std::string> f;
  size_t at = 0;
  for (size_t comma; (comma = s.drawn.find(',', at)) != std::string::npos; at = comma + 1)
    f.push_back(s.drawn.substr(at, comma - at));
  f.push_back(s.drawn.substr(at));
  char stature[32];
  std::snprintf(stature, sizeof stature, "%.2f m", std::atof(f[1].c_str()) / 1000);
  return f[0] + ", " + stature + ", " + f[7];
}

namespace {

// Bodies [first, first + count) as the catalogue's subjects, every view's places derived again.
void use_bodies(Catalogue& cat, uint64_t seed, uint64_t first, int count) {
  std::vector<Subject> bodies;
  for (int k = 0; k < count; ++k) bodies.push_back(draw_body(cat, seed, first + k));
  cat.subjects = std::move(bodies);
  for (Sensor& s : cat.sensors) derive_places(cat, s);
}

}  // namespace

void use_random_bodies(Catalogue& cat, uint64_t seed, int count) { use_bodies(cat, seed, 0, count); }

void use_page_bodies(Catalogue& cat, uint64_t seed, uint64_t page) {
  use_bodies(cat, seed, page * kBodyPage, kBodyPage);
}

}  // namespace portalsim
