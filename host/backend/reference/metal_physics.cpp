// Metal zones under --model physics (docs/model/metal.md): each zone is a
// transmit coil on its own panel and a receive coil on the other, both magnetic dipoles;
// an object at p with polarizability tensor M gives H_R(p)^T M H_T(p) (Marsh et al. 2014),
// and the objects' signals add. Plain double precision, one zone and object at a time.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

namespace {

struct Vec {
  double x, y, z;
};

// Field of a dipole of moment m at c, seen at p: (3 (m.r) r / |r|^2 - m) / (4 pi |r|^3).
Vec dipole(Vec m, Vec c, Vec p) {
  const Vec r{p.x - c.x, p.y - c.y, p.z - c.z};
  const double d2 = r.x * r.x + r.y * r.y + r.z * r.z;
  const double d = std::sqrt(d2);
  const double k = 3.0 * (m.x * r.x + m.y * r.y + m.z * r.z) / d2;
  const double den = 4 * std::numbers::pi * d2 * d;
  return {(k * r.x - m.x) / den, (k * r.y - m.y) / den, (k * r.z - m.z) / den};
}

// A zone's deduction from its response gain |signal|: rounded half up; anything at or past
// the cap (or not finite, an object on a coil) is the cap.
int deduction_of(double t) {
  constexpr int kMaxDeduction = 199;  // a zone reads at least 1 from its base of 200
  return t < kMaxDeduction ? static_cast<int>(std::floor(t + 0.5)) : kMaxDeduction;
}

}  // namespace

std::vector<MetalObject> metal_objects(const Catalogue& cat, const AssetSet& assets, const ModelSettings& m,
                                       const Scenario& s, uint64_t index) {
  const MetalPhysics& mp = cat.metal_physics;
  const double scale = cat.metres_per_field_unit();
  std::vector<MetalObject> out;
  // Each region's object where the first view that sees it places it, with that view's
  // composite's jitter, in the portal's field; in region order.
  std::vector<std::optional<ViewScene>> scenes(cat.sensors.size());
  for (int r = 0; r < cat.region_count(); ++r) {
    const int k = first_view(cat.sensors, r);
    if (s.objects[r] == kNoObject || k < 0) continue;
    const Sensor& sensor = cat.sensors[k];
    if (!scenes[k]) scenes[k].emplace(view_scene(cat, assets, m, k, s, index));
    // Its sprites are in region order: this region's is after those of the regions before.
    size_t next = 0;
    for (int before = 0; before < r; ++before) next += s.objects[before] != kNoObject && sensor.sees(before);
    const Placed& p = scenes[k]->placed[next];
    const Rect rc = sensor.place(s.subject, r);
    const double col = sensor.field_col(rc.x + rc.w / 2.0) + p.dx * sensor.field_per_col();
    const double row = sensor.field_row(rc.y + rc.h / 2.0) + p.dy * sensor.field_per_row();
    const std::array<double, 2> side = cat.long_side(s.objects[r]);
    out.push_back({cat.polarizability(s.objects[r]), (col - kFieldWidth / 2.0) * scale, mp.body_height - row * scale,
                   side[0], side[1]});
  }
  return out;
}

double zone_signal(const MetalPhysics& mp, int zone, const MetalObject& o) {
  const double side = mp.tx_side[zone];
  const Vec tx{side * mp.panel_separation / 2.0, 0.0, mp.tx_height[zone]};
  const Vec rx{-side * mp.panel_separation / 2.0, 0.0, mp.rx_height[zone]};
  const std::array<double, 9>& M = o.tensor;
  double sum = 0;
  for (int k = 0; k < PS_METAL_SEGMENTS; ++k) {
    const double f = (k + 0.5) / PS_METAL_SEGMENTS - 0.5;  // along the long side, -1/2 .. 1/2
    const Vec p{o.x + f * o.lx, o.y + f * o.ly, o.z + f * o.lz};
    // Both coils' moments point into the portal.
    const Vec ht = dipole({-side * mp.tx_moment, 0.0, 0.0}, tx, p);
    const Vec hr = dipole({side * mp.rx_moment, 0.0, 0.0}, rx, p);
    const double v0 = M[0] * ht.x + M[1] * ht.y + M[2] * ht.z;
    const double v1 = M[3] * ht.x + M[4] * ht.y + M[5] * ht.z;
    const double v2 = M[6] * ht.x + M[7] * ht.y + M[8] * ht.z;
    sum += hr.x * v0 + hr.y * v1 + hr.z * v2;
  }
  return sum / PS_METAL_SEGMENTS;
}

void metal_physics(const Catalogue& cat, const AssetSet& assets, const ModelSettings& m, const Scenario& s,
                   uint64_t index, uint8_t* zones) {
  const MetalPhysics& mp = cat.metal_physics;
  const std::vector<MetalObject> objects = metal_objects(cat, assets, m, s, index);
  const int noise = m.metal_noise;
  for (int z = 0; z < cat.zones; ++z) {
    double signal = 0;
    for (const MetalObject& o : objects) signal += zone_signal(mp, z, o);
    const int deduction = deduction_of(mp.gain[z] * std::fabs(signal));
    int value = cat.subjects[s.subject].base_zones[z] - deduction;
    if (noise > 0 && deduction > 0) {
      const Philox4 r = draw(m.seed, index, kStreamMetalNoise, static_cast<uint32_t>(z));
      value += static_cast<int>(below(r[0], noise + 1)) - static_cast<int>(below(r[1], noise + 1));
    }
    zones[z] = static_cast<uint8_t>(std::clamp(value, 1, 200));
  }
}

void metal_response(const MetalPhysics& mp, const MetalObject& o, double* response, uint8_t* deduction) {
  for (size_t z = 0; z < mp.gain.size(); ++z) {
    response[z] = mp.gain[z] * std::fabs(zone_signal(mp, static_cast<int>(z), o));
    deduction[z] = static_cast<uint8_t>(deduction_of(response[z]));
  }
}

}  // namespace portalsim::reference
