// The metal detector under --model physics: dipole fall-off, additivity, orientation,
// jitter, the worked examples pinned and within the fit's residual, exact parity of the kernel with
// the reference, and the catalogue's checks of [metal.physics].
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"
#include "base/embedded.h"
#include "base/error.h"
#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;
using test::line_of;
using test::replace_once;

ModelSettings physics() {
  ModelSettings m;
  m.model = Model::physics;
  return m;
}

std::vector<int> zones(Backend& b, const std::vector<std::string>& objects, const ModelSettings& m = physics()) {
  return test::metal_zones(b, parse_object_list(catalogue(), objects), m);
}

// One zone's signal of an isotropic object of 1 cm^3 on the line between the zone's coils,
// both set at height h: the transmit field on its axis is 2 m_T / (4 pi d_T^3), the
// receive field -2 m_R / (4 pi d_R^3) (its moment points the other way, into the portal).
TEST(MetalPhysics, ZoneSignalFallsAsTheProductOfTwoDipoleFields) {
  MetalPhysics mp = catalogue().metal_physics;
  ASSERT_TRUE(mp.present);
  const double h = 1.1;
  for (int zone : {2, 14}) {
    mp.tx_height[zone] = mp.rx_height[zone] = h;
    const double side = mp.tx_side[zone];
    const double tx_x = side * mp.panel_separation / 2, rx_x = -tx_x;
    double last = 0;
    for (double f = 0.05; f <= 0.951; f += 0.05) {
      const double x = tx_x + (rx_x - tx_x) * f;  // from the transmit panel towards the receive one
      const reference::MetalObject o{{1, 0, 0, 0, 1, 0, 0, 0, 1}, x, h};
      const double dt = std::fabs(x - tx_x), dr = std::fabs(x - rx_x);
      const double want =
          (2 * mp.tx_moment / (4 * M_PI * dt * dt * dt)) * (-2 * mp.rx_moment / (4 * M_PI * dr * dr * dr));
      const double got = reference::zone_signal(mp, zone, o);
      EXPECT_NEAR(got / want, 1.0, 1e-12) << "zone " << zone + 1 << " at " << f;
      if (f > 0.05) {
        EXPECT_NE(got, last);
      }
      last = got;
    }
  }
}

// A point straight above a transmit coil (along the panel) sees -m_T / (4 pi d^3): the
// fall-off is 1/d^3 in that direction too.
TEST(MetalPhysics, FieldAlongThePanelIsMinusHalfTheAxialField) {
  MetalPhysics mp = catalogue().metal_physics;
  const int zone = 4;
  const double tx_x = -mp.panel_separation / 2, rx_x = -tx_x;
  for (double d : {0.1, 0.2, 0.4, 0.8}) {
    mp.tx_height[zone] = 1.0;
    mp.rx_height[zone] = 1.0 + d;
    // The object d above the transmit coil (moment +x: field -m_T / (4 pi d^3)), at the
    // receive coil's height, so on the receive coil's axis (moment -x).
    const reference::MetalObject o{{1, 0, 0, 0, 1, 0, 0, 0, 1}, tx_x + 1e-9, 1.0 + d};
    const double ht = -mp.tx_moment / (4 * M_PI * d * d * d);
    const double dr = rx_x - (tx_x + 1e-9);
    const double hr = 2 * -mp.rx_moment / (4 * M_PI * dr * dr * dr);
    EXPECT_NEAR(reference::zone_signal(mp, zone, o) / (ht * hr), 1.0, 1e-6) << d;
  }
}

// Each zone has its own gain (its channel's sensitivity): doubling zone 14's doubles its
// deduction (within rounding) and leaves every other zone as it was.
TEST(MetalPhysics, EachZoneHasItsOwnGain) {
  Catalogue cat = catalogue();
  const Scenario s = parse_object_list(cat, {"none", "none", "none", "none", "none", "none", "compact-disk"});
  std::array<uint8_t, kBuiltinZones> before{}, after{};
  reference::metal_physics(cat, assets(), physics(), s, 0, before.data());
  const int zone = 13;
  cat.metal_physics.gain[zone] *= 2;
  reference::metal_physics(cat, assets(), physics(), s, 0, after.data());
  for (int z = 0; z < kBuiltinZones; ++z) {
    const int d0 = 200 - before[z], d1 = 200 - after[z];
    if (z == zone) {
      ASSERT_GT(d0, 0);
      EXPECT_NEAR(d1, 2 * d0, 1);
    } else {
      EXPECT_EQ(d1, d0) << "zone " << z + 1;
    }
  }
}

// An anisotropic object's strong axis is its drawing's long side: along z for a drawing
// taller than wide (the pendant, 14 x 22), along x once it is drawn wider than tall.
TEST(MetalPhysics, TheStrongAxisIsTheDrawingsLongSide) {
  std::string text(embedded::default_catalogue);
  const std::string pendant = "name = \"pendant\"\n";
  text.insert(text.find(pendant) + pendant.size(), "metal_anisotropy = 4.0\n");
  Catalogue cat = parse_catalogue(text, "a.toml", "", "");
  const int v = cat.objects[cat.find_object("pendant")].first_variant;
  const auto tall = cat.polarizability(v);
  EXPECT_EQ(cat.long_side(v)[0], 0.0);
  EXPECT_NEAR(tall[8], 4.0 * tall[0], 1e-9 * tall[8]) << "zz is a times xx";
  EXPECT_EQ(tall[4], tall[0]);
  cat.objects[cat.find_object("pendant")].width = 30;  // now wider than tall
  const auto wide = cat.polarizability(v);
  EXPECT_NEAR(wide[0], 4.0 * wide[8], 1e-9 * wide[0]) << "xx is a times zz";
}

// A long object is PS_METAL_SEGMENTS equal dipoles spread along its long side: its signal
// is the mean of point objects at the midpoints of equal segments (a rod of 56 MMW pixels,
// 24.5 cm, along x and along z), and the rod's long side is the catalogue's drawing.
TEST(MetalPhysics, LongObjectsAreDipolesAlongTheirLength) {
  const Catalogue& cat = catalogue();
  const double scale = cat.metal_physics.body_height / 400.0;  // the field: the two 200-pixel MMW views
  const int rod_h = cat.find_object("iron-rod"), rod = cat.objects[rod_h].first_variant;
  EXPECT_NEAR(cat.long_side(rod)[0], 56 * scale, 1e-12);
  EXPECT_EQ(cat.long_side(rod)[1], 0.0);
  EXPECT_EQ(cat.long_side(rod + 1)[0], 0.0);  // the "v" drawing: along z
  EXPECT_NEAR(cat.long_side(rod + 1)[1], 56 * scale, 1e-12);
  for (const auto& side : {cat.long_side(rod), cat.long_side(rod + 1)}) {
    const reference::MetalObject o{cat.polarizability(rod), 0.1, 1.1, side[0], side[1]};
    for (int z = 0; z < kBuiltinZones; ++z) {
      double sum = 0, size = 0;
      for (int k = 0; k < 5; ++k) {
        const double f = -0.4 + 0.2 * k;
        const double s =
            reference::zone_signal(cat.metal_physics, z, {o.tensor, o.x + f * side[0], o.z + f * side[1], 0.0, 0.0});
        sum += s;
        size += std::fabs(s);
      }
      // Within float sums' rounding of the terms' size.
      EXPECT_NEAR(reference::zone_signal(cat.metal_physics, z, o), sum / 5, 1e-12 * size) << "zone " << z + 1;
    }
  }
}

class MetalPhysicsBothBackends : public test::BothBackends {};

// Signals of separate objects add: where both push a zone the same way and nothing
// saturates, the pair's deduction is the sum of each one's (each rounded: within 1).
TEST_P(MetalPhysicsBothBackends, TwoDistantObjectsAdd) {
  auto b = backend();
  const std::vector<std::string> a{"iron-handle"},
      c{"none", "none", "none", "none", "none", "none", "none", "none", "none", "none", "none", "none", "metal-strip"};
  std::vector<std::string> both = c;
  both[0] = "iron-handle";
  const auto za = zones(*b, a), zc = zones(*b, c), zb = zones(*b, both);
  const Catalogue& cat = catalogue();
  const auto objs_a = reference::metal_objects(cat, assets(), physics(), parse_object_list(cat, a), 0);
  const auto objs_c = reference::metal_objects(cat, assets(), physics(), parse_object_list(cat, c), 0);
  int checked = 0;
  for (int z = 0; z < kBuiltinZones; ++z) {
    const double sa = reference::zone_signal(cat.metal_physics, z, objs_a[0]);
    const double sc = reference::zone_signal(cat.metal_physics, z, objs_c[0]);
    const int da = 200 - za[z], dc = 200 - zc[z], db = 200 - zb[z];
    if ((sa >= 0) != (sc >= 0) || da + dc >= 190) continue;
    EXPECT_NEAR(db, da + dc, 1) << "zone " << z + 1;
    ++checked;
  }
  EXPECT_GE(checked, 10);
  // Each one alone moves some zone: neither is invisible.
  EXPECT_NE(za, std::vector<int>(kBuiltinZones, 200));
  EXPECT_NE(zc, std::vector<int>(kBuiltinZones, 200));
}

// The gun's and the rod's horizontal and vertical drawings have different tensors, so the
// zones differ; the thesis model gives them the same row.
TEST_P(MetalPhysicsBothBackends, OrientationMatters) {
  auto b = backend();
  for (const char* obj : {"gun", "iron-rod"}) {
    for (int region : {0, 4, 9}) {
      std::vector<std::string> h(region + 1, "none"), v(region + 1, "none");
      h[region] = std::string(obj) + ":h";
      v[region] = std::string(obj) + ":v";
      EXPECT_NE(zones(*b, h), zones(*b, v)) << obj << " in region " << region + 1;
      EXPECT_EQ(zones(*b, h, ModelSettings{}), zones(*b, v, ModelSettings{})) << obj << " under the thesis model";
    }
  }
}

// Any metal anywhere responds, and none leaves the subject's base alone.
TEST_P(MetalPhysicsBothBackends, EveryRegionRespondsAndNonMetalDoesNot) {
  auto b = backend();
  for (int r = 0; r < kBuiltinRegions; ++r) {
    std::vector<std::string> objs(r + 1, "none");
    objs[r] = "iron-handle";  // medium metal
    EXPECT_NE(zones(*b, objs), std::vector<int>(kBuiltinZones, 200)) << "region " << r + 1;
    objs[r] = "ceramic-plate";
    EXPECT_EQ(zones(*b, objs), std::vector<int>(kBuiltinZones, 200)) << "region " << r + 1;
  }
}

// The three worked examples under the physics model, pinned value by value (both backends
// compute them exactly), and their rms residual against the thesis within the fit's
// (docs/model/metal.md; tools/fit_metal_coils.py reports it). A refit of
// [metal.physics] changes the pinned values: copy them from the fit's report.
TEST_P(MetalPhysicsBothBackends, WorkedExamplesArePinnedAndNearTheThesis) {
  auto b = backend();
  struct Example {
    std::vector<std::string> objects;
    std::vector<int> thesis, physics;
    double rms_bound;  // the fit's rms residual, rounded up to 0.1
  };
  const std::vector<Example> examples{
      {{"none", "none", "none", "Gun"},
       {193, 112, 75, 2, 1, 1, 96, 200, 200, 190, 196, 53, 53, 94, 64, 82, 53, 200, 200},
       {196, 112, 75, 2, 1, 2, 98, 199, 200, 191, 197, 53, 53, 85, 59, 90, 56, 197, 200},
       3.3},
      {{"none", "none", "metal-barrel"},
       {197, 131, 108, 88, 95, 106, 192, 200, 200, 197, 199, 54, 54, 75, 44, 84, 137, 200, 200},
       {197, 130, 108, 81, 94, 104, 186, 200, 200, 199, 199, 54, 54, 89, 51, 79, 137, 199, 200},
       4.4},
      {{"none", "none", "Mobile", "none", "none", "none", "compact-disk"},
       {200, 183, 165, 136, 137, 142, 193, 200, 200, 198, 199, 185, 185, 195, 176, 175, 190, 200, 200},
       {198, 189, 162, 160, 140, 143, 186, 198, 199, 200, 198, 179, 180, 182, 173, 187, 187, 199, 200},
       7.6}};
  for (const Example& e : examples) {
    const auto got = zones(*b, e.objects);
    EXPECT_EQ(got, e.physics) << e.objects.back();
    double sum = 0;
    for (int z = 0; z < kBuiltinZones; ++z) sum += double(got[z] - e.thesis[z]) * (got[z] - e.thesis[z]);
    EXPECT_LE(std::sqrt(sum / kBuiltinZones), e.rms_bound) << e.objects.back();
    // The thesis model still gives the thesis's numbers exactly.
    EXPECT_EQ(zones(*b, e.objects, ModelSettings{}), e.thesis);
  }
}

// Jitter moves each object continuously: small steps of the jitter amplitude move the
// zones by small steps, and a large one moves them.
TEST_P(MetalPhysicsBothBackends, JitterMovesTheResponseContinuously) {
  auto b = backend();
  ModelSettings m = physics();
  m.seed = 7;
  const std::vector<std::string> objs{"none", "none", "none", "none", "metal-strip"};
  std::vector<int> prev = zones(*b, objs, m), first = prev;
  for (int k = 1; k <= 60; ++k) {
    m.jitter = 0.25 * k;  // up to 15 MMW pixels, about 6.6 cm
    const auto z = zones(*b, objs, m);
    for (int j = 0; j < kBuiltinZones; ++j)
      EXPECT_LE(std::abs(z[j] - prev[j]), 4) << "zone " << j + 1 << " jitter " << m.jitter;
    prev = z;
  }
  int moved = 0;
  for (int j = 0; j < kBuiltinZones; ++j) moved += std::abs(prev[j] - first[j]);
  EXPECT_GE(moved, 10);
}

INSTANTIATE_TEST_SUITE_P(, MetalPhysicsBothBackends, ::testing::Values("reference", "opencl"));

// The kernel computes in fp64 with the reference's operations in its order: the integer
// zones match exactly, over random scenes, jitter, detector noise and every tier.
TEST(MetalPhysicsParity, KernelMatchesReferenceExactly) {
  auto ref = make_reference_backend(catalogue(), assets());
  auto ocl = make_opencl_backend(catalogue(), assets(), test::runtime());
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 3000; ++k) scenes.push_back(test::random_scenario(catalogue(), k));
  const SceneBatch batch = test::batch_of(scenes, 1000);
  int config = 0;
  for (double jitter : {0.0, 3.7, 40.0})
    for (int noise : {0, 5})
      for (Tier tier : {Tier::standard, Tier::fast, Tier::exact}) {
        Plan plan;
        plan.images = 0;
        plan.features = false;
        plan.model = physics();
        plan.model.seed = 1234 + config++;
        plan.model.jitter = jitter;
        plan.model.metal_noise = noise;
        plan.fidelity = tier_fidelity(tier);
        BatchOutput a, b;
        ref->run(batch, plan, a);
        ocl->run(batch, plan, b);
        ASSERT_EQ(a.metal.size(), b.metal.size());
        size_t differ = 0;
        for (size_t i = 0; i < a.metal.size(); ++i) differ += a.metal[i] != b.metal[i];
        EXPECT_EQ(differ, 0u) << "jitter " << jitter << " noise " << noise << " tier " << tier_name(tier);
      }
}

// "key = [first," as it stands in the text.
std::string first_element(const std::string& text, const std::string& key) {
  const size_t at = text.find(key);
  return text.substr(at, text.find(',', at) + 1 - at);
}

// Each bad value is rejected naming file, line and field.
TEST(MetalPhysicsCatalogue, BadValuesNameFileLineAndField) {
  const std::string text = test::default_catalogue_text();
  struct Case {
    std::string from, to, field, line_of;
  };
  const std::vector<Case> cases{
      {"panel_separation = ", "panel_separation = nan #", "metal.physics.panel_separation", "panel_separation = "},
      {"body_height = ", "body_height = 9.0 #", "metal.physics.body_height", "body_height = "},
      {first_element(text, "tx_height = ["), "tx_height = [-1.0,", "metal.physics.tx_height[0]", "tx_height = ["},
      {first_element(text, "rx_height = ["), "rx_height = [inf,", "metal.physics.rx_height[0]", "rx_height = ["},
      {"gain = [", "gain = [1.0, ", "metal.physics.gain", "gain = ["},
      {"\nheavy = 1", "\nheavy = -1", "metal.physics.polarizability.heavy", "\nheavy = 1"},
      {"\nheavy = 1", "\nplutonium = 3.0\nheavy = 1", "metal.physics.polarizability.plutonium", "\nheavy = 1"},
      {"tx_moment = ", "tx_moment = \"one\" #", "metal.physics.tx_moment", "tx_moment = "},
      {"metal_anisotropy = 1.6", "metal_anisotropy = 0.5", "objects[1].metal_anisotropy", "metal_anisotropy = 1.6"},
  };
  for (const Case& c : cases) {
    const std::string bad = replace_once(text, c.from, c.to);
    const int line = line_of(text, c.line_of) + (c.line_of[0] == '\n' ? 1 : 0);
    try {
      parse_catalogue(bad, "cat.toml", "");
      ADD_FAILURE() << "accepted " << c.to;
    } catch (const InputError& e) {
      const std::string want = "cat.toml:" + std::to_string(line) + ": " + c.field;
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what() << "\nwanted " << want;
    }
  }
  // Without [metal.physics] the thesis model runs and the physics model is refused.
  const size_t begin = text.find("# BEGIN metal physics"), end = text.find("# END metal physics");
  ASSERT_NE(begin, std::string::npos);
  const Catalogue none = parse_catalogue(text.substr(0, begin) + text.substr(end), "cat.toml", "");
  EXPECT_FALSE(none.metal_physics.present);
  Plan plan;
  EXPECT_NO_THROW(validate(plan, none));
  plan.model.model = Model::physics;
  EXPECT_THROW(validate(plan, none), InputError);
}

}  // namespace
}  // namespace portalsim
