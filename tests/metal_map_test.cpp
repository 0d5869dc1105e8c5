// Metal detector sensitivity maps (host/evaluate/metal_map.h, `portalsim evaluate
// --metal-map`): the physics model's object along the walk and in any orientation, kernel
// against reference; the map's invariants (panels' symmetry, fall-off along the walk,
// orientation, no metal no alarm), its threshold against the stated Pfa, determinism, and
// the command's refusals.
#include "backend/opencl/metal_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "backend/reference/stages.h"
#include "evaluate/metal_map.h"
#include "run_binary.h"
#include "scene/philox.h"
#include "support.h"

namespace portalsim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::catalogue;

constexpr std::array<std::array<double, 3>, 3> kAxes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

// An object record (PS_MV_*) of `object` with its long axis along unit vector u.
void add_record(std::vector<double>& rec, const Catalogue& cat, const std::string& object,
                const std::array<double, 3>& u) {
  const int v = cat.objects[cat.find_object(object)].first_variant;
  const auto side = cat.long_side(v);
  const double length = std::max(side[0], side[1]);
  const auto t = cat.polarizability(v, u);
  rec.insert(rec.end(), t.begin(), t.end());
  rec.push_back(u[0] * length);  // PS_MV_LONG_X
  rec.push_back(u[2] * length);  // PS_MV_LONG_Z
  rec.push_back(u[1] * length);  // PS_MV_LONG_Y
}

reference::MetalObject object_of(const std::vector<double>& rec, int k, double x, double y, double z) {
  const double* r = &rec[static_cast<size_t>(k) * PS_MV_LEN];
  reference::MetalObject o{};
  std::copy(r, r + 9, o.tensor.begin());
  o.x = x;
  o.y = y;
  o.z = z;
  o.lx = r[PS_MV_LONG_X];
  o.ly = r[PS_MV_LONG_Y];
  o.lz = r[PS_MV_LONG_Z];
  return o;
}

// The kernel's responses and deductions against the reference's, for objects anywhere along
// the walk and in any orientation (oblique axes included), and at the extremes: at a panel,
// on the floor, on a coil (not finite: the cap), far along the walk. Deductions exactly, the
// unrounded responses to the bit (both fp64, the same operations in the same order).
TEST(MetalMapParity, KernelMatchesReferenceAlongTheWalkInAnyOrientation) {
  const Catalogue& cat = catalogue();
  const MetalPhysics& mp = cat.metal_physics;
  std::vector<double> rec;
  int records = 0;
  for (const char* name : {"gun", "iron-rod", "mobile-phone", "ceramic-plate"}) {
    for (const auto& u : kAxes) add_record(rec, cat, name, u), ++records;
    for (uint32_t k = 0; k < 4; ++k) {  // oblique axes
      const Philox4 r = draw(7, k, 99, 0);
      std::array<double, 3> u{uniform24(r[0]) - 0.5, uniform24(r[1]) - 0.5, uniform24(r[2]) - 0.5};
      const double n = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (double& c : u) c /= n;
      add_record(rec, cat, name, u), ++records;
    }
  }
  std::vector<double> probes;
  const double half = mp.panel_separation / 2;
  for (uint32_t k = 0; k < 4000; ++k) {
    const Philox4 r = draw(11, k, 98, 0);
    probes.insert(probes.end(), {(2 * uniform24(r[0]) - 1) * half, (2 * uniform24(r[1]) - 1) * 1.5,
                                 uniform24(r[2]) * 2.1, static_cast<double>(r[3] % records)});
  }
  for (int o = 0; o < records; ++o)
    for (const std::array<double, 3>& p :
         std::vector<std::array<double, 3>>{{half - 1e-3, 0, 1.0},        // at panel B
                                            {-half + 1e-3, 0.05, 1.2},    // at panel A
                                            {0, 0, 0},                    // on the floor
                                            {0.1, 0.3, 0},                // on the floor, along the walk
                                            {0, 5, 1},                    // far along the walk
                                            {0, -50, 1},                  // farther
                                            {half, 0, mp.tx_height[12]},  // on zone 13's transmit coil
                                            {-half, 0, mp.rx_height[12]}}) {
      probes.insert(probes.end(), {p[0], p[1], p[2], static_cast<double>(o)});
    }
  const size_t n = probes.size() / PS_MP_LEN;
  const opencl::MetalResponses got = opencl::metal_responses(*test::runtime(), cat, rec, probes);
  ASSERT_EQ(got.deduction.size(), n * kBuiltinZones);
  size_t differ = 0, capped = 0;
  for (size_t i = 0; i < n; ++i) {
    const double* p = &probes[i * PS_MP_LEN];
    std::array<double, kBuiltinZones> response{};
    std::array<uint8_t, kBuiltinZones> deduction{};
    reference::metal_response(mp, object_of(rec, static_cast<int>(p[3]), p[0], p[1], p[2]), response.data(),
                              deduction.data());
    for (int z = 0; z < kBuiltinZones; ++z) {
      const double k = got.response[i * kBuiltinZones + z];
      const bool same = k == response[z] || (std::isnan(k) && std::isnan(response[z]));
      differ += !same || got.deduction[i * kBuiltinZones + z] != deduction[z];
      capped += deduction[z] == 199;
    }
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(capped, 0u) << "the extremes reach the cap";
}

// The tensor in any orientation: along x and z it is polarizability(variant)'s to the bit;
// along an oblique axis it is m 3 / (a + 2) (I + (a - 1) u u^T), computed here by hand.
TEST(MetalMap, PolarizabilityInAnyOrientationHandComputed) {
  const Catalogue& cat = catalogue();
  const int gun = cat.objects[cat.find_object("gun")].first_variant;
  EXPECT_EQ(cat.polarizability(gun, {1, 0, 0}), cat.polarizability(gun));
  const int rod_v = cat.objects[cat.find_object("iron-rod")].first_variant + 1;  // "v": along z
  EXPECT_EQ(cat.polarizability(rod_v, {0, 0, 1}), cat.polarizability(rod_v));
  // The gun: heavy, 100 cm^3, a = 1.6: across 100 * 3 / 3.6.
  const double s = std::sqrt(0.5), across = 100 * 3 / 3.6;
  const auto t = cat.polarizability(gun, {s, s, 0});
  const std::array<double, 9> want{across * 1.3, across * 0.3, 0, across * 0.3, across * 1.3, 0, 0, 0, across};
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(t[i], want[i], 1e-12) << i;
}

// A symmetric portal (zones 10-18 the mirror of zones 1-9): an object at -x reads in zone
// 10 + k what it reads at +x in zone 1 + k, in every orientation and along the walk.
TEST(MetalMap, PanelsAreMirrorImages) {
  MetalPhysics mp = catalogue().metal_physics;
  for (int k = 0; k < 9; ++k) {
    mp.tx_height[9 + k] = mp.tx_height[k];
    mp.rx_height[9 + k] = mp.rx_height[k];
    mp.gain[9 + k] = mp.gain[k];
  }
  std::vector<double> rec;
  for (const auto& u : kAxes) add_record(rec, catalogue(), "gun", u);
  int checked = 0;
  for (int o = 0; o < 3; ++o)
    for (double x : {0.05, 0.15, 0.25})
      for (double y : {0.0, 0.2, -0.4})
        for (double z : {0.3, 1.0, 1.4}) {
          std::array<double, kBuiltinZones> a{}, b{};
          std::array<uint8_t, kBuiltinZones> da{}, db{};
          reference::metal_response(mp, object_of(rec, o, x, y, z), a.data(), da.data());
          reference::metal_response(mp, object_of(rec, o, -x, y, z), b.data(), db.data());
          for (int k = 0; k < 9; ++k) {
            EXPECT_NEAR(a[k], b[9 + k], 1e-9 * std::max(1.0, a[k])) << "zone " << k + 1;
            EXPECT_NEAR(a[9 + k], b[k], 1e-9 * std::max(1.0, a[9 + k])) << "zone " << k + 10;
            checked += a[k] > 1;
          }
        }
  EXPECT_GT(checked, 50);
}

// Walking away from the coils' plane (y = 0, where the coils are), each zone's response stays
// under the envelope of two dipoles' strongest fields, 2 m / (4 pi d^3) at the object's
// distance d from each coil (segment by segment), so it falls at least as 1/d^6; alike either
// way along the walk; and 3 m along it is under 1% of its peak. (Not monotonic: a dipole's
// field across the walk changes sign 54.7 degrees off its axis, so a zone can read a second,
// weaker lobe.)
TEST(MetalMap, ResponseFallsWithDistanceToTheCoils) {
  const MetalPhysics& mp = catalogue().metal_physics;
  std::vector<double> rec;
  for (const auto& u : kAxes) add_record(rec, catalogue(), "gun", u);
  const double lmax = *std::max_element(rec.begin(), rec.begin() + 9);  // the tensor's largest eigenvalue
  auto responses = [&](int o, double x, double y, double z) {
    std::array<double, kBuiltinZones> r{};
    std::array<uint8_t, kBuiltinZones> d{};
    reference::metal_response(mp, object_of(rec, o, x, y, z), r.data(), d.data());
    return r;
  };
  int checked = 0;
  for (int o = 0; o < 3; ++o)
    for (double x : {-0.2, 0.0, 0.2})
      for (double z : {0.4, 1.0, 1.5}) {
        double peak = 0, far = 0;
        for (double y : {0.0, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0, 1.5, 2.0, 3.0}) {
          const auto r = responses(o, x, y, z), back = responses(o, x, -y, z);
          for (int zone = 0; zone < kBuiltinZones; ++zone) {
            const double side = mp.tx_side[zone];
            double bound = 0;
            for (int k = 0; k < PS_METAL_SEGMENTS; ++k) {
              const double f = (k + 0.5) / PS_METAL_SEGMENTS - 0.5;
              const double px = x + f * rec[o * PS_MV_LEN + PS_MV_LONG_X],
                           py = y + f * rec[o * PS_MV_LEN + PS_MV_LONG_Y],
                           pz = z + f * rec[o * PS_MV_LEN + PS_MV_LONG_Z];
              const double dt = std::hypot(px - side * mp.panel_separation / 2, py, pz - mp.tx_height[zone]);
              const double dr = std::hypot(px + side * mp.panel_separation / 2, py, pz - mp.rx_height[zone]);
              bound += lmax * (2 * mp.tx_moment / (4 * M_PI * dt * dt * dt)) *
                       (2 * mp.rx_moment / (4 * M_PI * dr * dr * dr));
            }
            bound = mp.gain[zone] * bound / PS_METAL_SEGMENTS;
            EXPECT_LE(r[zone], bound * (1 + 1e-9)) << "axis " << o << " zone " << zone + 1 << " y " << y;
            EXPECT_NEAR(back[zone], r[zone], 1e-9 * std::max(1e-6, r[zone])) << "the walk's two sides";
            ++checked;
          }
          const double strongest = *std::max_element(r.begin(), r.end());
          peak = std::max(peak, strongest);
          if (y == 3.0) far = strongest;
        }
        EXPECT_LT(far, 0.01 * peak);
      }
  EXPECT_GT(checked, 1000);
}

// An anisotropic object's response depends on its orientation; an isotropic point does not.
TEST(MetalMap, OrientationMattersOnlyForAnAnisotropicObject) {
  const MetalPhysics& mp = catalogue().metal_physics;
  auto response = [&](const std::array<double, 9>& t, double z) {
    std::array<double, kBuiltinZones> r{};
    std::array<uint8_t, kBuiltinZones> d{};
    reference::MetalObject o{t, 0.1, z};
    reference::metal_response(mp, o, r.data(), d.data());
    return r;
  };
  const Catalogue& cat = catalogue();
  const int rod = cat.objects[cat.find_object("iron-rod")].first_variant;
  for (double z : {0.5, 1.0, 1.4}) {
    const auto rx = response(cat.polarizability(rod, {1, 0, 0}), z),
               ry = response(cat.polarizability(rod, {0, 1, 0}), z),
               rz = response(cat.polarizability(rod, {0, 0, 1}), z);
    // The coils' fields at the aperture point mostly across (x): the rod across reads several
    // times more than along the walk, in the strongest zone.
    const double mx = *std::max_element(rx.begin(), rx.end()), my = *std::max_element(ry.begin(), ry.end());
    EXPECT_GT(mx, 2 * my) << z;
    EXPECT_NE(rz, ry);
    // The pendant is isotropic (anisotropy 1): one tensor, one response, whatever its axis.
    const int pendant = cat.objects[cat.find_object("pendant")].first_variant;
    EXPECT_EQ(response(cat.polarizability(pendant, {1, 0, 0}), z), response(cat.polarizability(pendant, {0, 1, 0}), z));
    EXPECT_EQ(response(cat.polarizability(pendant, {1, 0, 0}), z), response(cat.polarizability(pendant, {0, 0, 1}), z));
  }
}

evaluate::MetalMapSettings small(const std::string& object) {
  evaluate::MetalMapSettings s;
  s.object = object;
  s.grid_step = 0.1;
  s.sample_rate = 20;
  s.passes = 40;
  s.threads = 2;
  return s;
}

// The gun's map shows the physics: cells differ (a sensitivity ratio well above 1), the
// orientations differ, and the critical orientation and position are named.
TEST(MetalMap, HandgunMapShowsRatioOrientationAndCriticalCell) {
  evaluate::MetalMapSettings s = small("handgun");
  s.settings = {20};
  const json m = evaluate::metal_map(catalogue(), s, test::runtime().get());
  EXPECT_EQ(m["object"], "gun");
  ASSERT_FALSE(m["sensitivity_ratio"].is_null());
  EXPECT_GT(m["sensitivity_ratio"].get<double>(), 10.0);
  std::vector<double> means;
  for (const json& o : m["orientations"]) {
    means.push_back(o["mean_pd"].get<double>());
    EXPECT_GT(o["reachable_cells"].get<int>(), 0);
  }
  // The orientation effect, at a less sensitive setting where cells differ: the gun along the
  // walk (y) is the hardest to see, its long axis across the coils' fields.
  const json& at20 = m["sensitivity_settings"][0];
  ASSERT_EQ(at20["sensitivity"], 20);
  const json& by = at20["pd_mean_by_orientation"];
  EXPECT_GT(by["x"].get<double>() - by["y"].get<double>(), 0.05);
  EXPECT_GT(by["z"].get<double>() - by["y"].get<double>(), 0.05);
  const json& c = m["critical"];
  ASSERT_FALSE(c.is_null());
  EXPECT_EQ(c["mean_pd"].get<double>(), *std::min_element(means.begin(), means.end()));
  // Across (x), the gun's ends would go into a panel in the outermost cells: those are null.
  EXPECT_TRUE(m["orientations"][0]["pd"][10][0].is_null());
  EXPECT_FALSE(m["orientations"][1]["pd"][10][0].is_null());
}

// An object without metal is mapped, not refused: Pd 0 in every cell and at every setting.
TEST(MetalMap, NonMetalObjectIsNeverDetected) {
  const json m = evaluate::metal_map(catalogue(), small("ceramic-plate"), test::runtime().get());
  size_t cells = 0;
  for (const json& o : m["orientations"]) {
    EXPECT_EQ(o["mean_pd"].get<double>(), 0.0);
    for (const json& row : o["pd"])
      for (const json& v : row)
        if (!v.is_null()) {
          EXPECT_EQ(v.get<double>(), 0.0);
          ++cells;
        }
  }
  EXPECT_GT(cells, 100u);
  EXPECT_TRUE(m["sensitivity_ratio"].is_null());
  for (const json& st : m["sensitivity_settings"]) EXPECT_EQ(st["pd_mean"].get<double>(), 0.0);
}

// The operating level is the most sensitive whose clean testers' false-alarm rate is within
// the stated Pfa: at that level within it, one level more sensitive past it.
TEST(MetalMap, ThresholdMeetsThePfaOnCleanTesters) {
  for (const auto& [benign, pfa] :
       std::vector<std::pair<bool, double>>{{false, 0.0}, {false, 0.5}, {true, 0.3}, {true, 0.9}}) {
    evaluate::MetalMapSettings s = small("gun");
    s.pfa = pfa;
    s.benign_clean = benign;
    const json m = evaluate::metal_map(catalogue(), s, test::runtime().get());
    const int level = m["threshold"]["sensitivity"].get<int>();
    ASSERT_GT(level, 0) << pfa;
    ASSERT_LT(level, 199) << pfa;
    EXPECT_LE(m["threshold"]["clean_false_alarm_rate"].get<double>(), pfa);
    s.settings = {level + 1};
    const json next = evaluate::metal_map(catalogue(), s, test::runtime().get());
    EXPECT_EQ(next["threshold"]["sensitivity"].get<int>(), level);
    const json& more = next["sensitivity_settings"][1];  // after the operating level
    ASSERT_EQ(more["sensitivity"].get<int>(), level + 1);
    EXPECT_GT(more["clean_false_alarm_rate"].get<double>(), pfa) << pfa;
  }
}

// A clean tester's walk passes the coils' plane at y = 0, where its item reads what the
// physics model gives that scenario (reference::metal_physics, no noise, no jitter).
TEST(MetalMap, CleanTesterAtTheCoilsPlaneReadsAsTheScenario) {
  const Catalogue& cat = catalogue();
  evaluate::MetalMapSettings s = small("gun");
  const evaluate::MetalWalks w = evaluate::metal_map_walks(cat, s);
  const opencl::MetalResponses r = opencl::metal_responses(*test::runtime(), cat, w.objects, w.probes);
  // The map's walks, then the clean testers: every standard benign item (the catalogue has
  // all eight, docs/model/objects.md) in every region of every subject.
  const size_t cells = w.walks - cat.subjects.size() * evaluate::kBenignItems.size() * kBuiltinRegions;
  const size_t at0 = static_cast<size_t>(std::lround(s.walk * s.sample_rate / s.speed));
  ASSERT_EQ(w.probes[(cells * w.samples + at0) * PS_MP_LEN + PS_MP_Y], 0.0);
  ModelSettings m;
  m.model = Model::physics;
  int checked = 0;
  for (size_t subject = 0; subject < cat.subjects.size(); ++subject)
    for (const char* item : evaluate::kBenignItems)
      for (int region = 0; region < kBuiltinRegions; ++region, ++checked) {
        Scenario sc;
        sc.subject = static_cast<int>(subject);
        sc.objects.fill(kNoObject);
        sc.objects[region] = cat.objects[cat.find_object(item)].first_variant;
        std::array<uint8_t, kBuiltinZones> zones{};
        reference::metal_physics(cat, test::assets(), m, sc, 0, zones.data());
        const size_t walk = cells + static_cast<size_t>(checked);
        for (int z = 0; z < kBuiltinZones; ++z)
          EXPECT_EQ(std::clamp(
                        cat.subjects[subject].base_zones[z] - r.deduction[(walk * w.samples + at0) * kBuiltinZones + z],
                        1, 200),
                    zones[z])
              << item << " region " << region + 1 << " zone " << z + 1;
      }
}

// The same settings give the same report to the byte: twice, on one thread or several, and
// from the kernels or the reference.
TEST(MetalMap, SameBytesEveryRunKernelsOrReference) {
  evaluate::MetalMapSettings s = small("gun");
  const std::string a = evaluate::metal_map(catalogue(), s, test::runtime().get()).dump();
  EXPECT_EQ(evaluate::metal_map(catalogue(), s, test::runtime().get()).dump(), a);
  s.threads = 1;
  EXPECT_EQ(evaluate::metal_map(catalogue(), s, nullptr).dump(), a);
  s.seed = 1;
  EXPECT_NE(evaluate::metal_map(catalogue(), s, nullptr).dump(), a) << "the seed draws the noise";
}

// --- The command.

using test::Result;
using test::TempDir;

Result run(const TempDir& t, std::vector<std::string> args) { return test::finish(test::start(t.cap(), args)); }

std::vector<std::string> map_args(const fs::path& out, std::vector<std::string> more = {}) {
  std::vector<std::string> a{"evaluate", "--metal-map", "gun", "--grid-step", "0.1",       "--sample-rate",
                             "20",       "--passes",    "20",  "--out",       out.string()};
  for (size_t k = 0; k < more.size(); ++k) {
    const auto at = std::find(a.begin(), a.end(), more[k]);
    if (k + 1 < more.size() && more[k].starts_with("--") && !more[k + 1].starts_with("--") && at != a.end()) {
      *(at + 1) = more[++k];  // a flag already there: its value replaced
    } else {
      a.push_back(more[k]);
    }
  }
  return a;
}

TEST(MetalMapCommand, WritesTheReportAndThePlot) {
  TempDir t;
  const fs::path out = t.w() / "map";
  const Result r = run(t, map_args(out));
  ASSERT_EQ(r.status, 0) << test::describe(r);
  for (const char* f : {"metal_map.json", "metal_map.md", "metal_map.png"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const json j = json::parse(test::slurp(out / "metal_map.json"));
  EXPECT_EQ(j["object"], "gun");
  EXPECT_TRUE(test::has(test::slurp(out / "metal_map.md"), "Critical orientation"));
  EXPECT_TRUE(test::has(r.out, "critical orientation"));
}

// The plot's script is run through the shell: a folder named with a quote and a command
// substitution is one word to it, and nothing in the name runs (cli/common.h, run_plot_script).
TEST(MetalMapCommand, AnyFolderNameIsOneWordToThePlot) {
  TempDir t;
  const fs::path out = t.w() / "it's $(touch pwned) map";
  const Result r = run(t, map_args(out));
  ASSERT_EQ(r.status, 0) << test::describe(r);
  EXPECT_TRUE(fs::exists(out / "metal_map.png"));
  EXPECT_FALSE(fs::exists(t.w() / "pwned"));
  EXPECT_FALSE(fs::exists(fs::current_path() / "pwned"));
}

// Each bad value is refused naming its flag, exit 2 (a bad flag value), no report folder.
TEST(MetalMapCommand, BadInputNamesTheFlagAndWritesNothing) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--metal-map", "unobtainium"}, "--metal-map"},
      {{"--grid-step", "2"}, "--grid-step"},
      {{"--grid-step", "0"}, "--grid-step"},
      {{"--speed", "0"}, "--speed"},
      {{"--speed", "-1"}, "--speed"},
      {{"--clean-pfa", "1.5"}, "--clean-pfa"},
      {{"--clean-pfa", "-0.1"}, "--clean-pfa"},
      {{"--sample-rate", "0"}, "--sample-rate"},
      {{"--passes", "0"}, "--passes"},
      {{"--sensitivity", "150,0"}, "--sensitivity"},
      {{"--metal-noise", "300"}, "--metal-noise"}};
  for (const auto& [more, flag] : cases) {
    TempDir t;
    const fs::path out = t.w() / "map";
    const Result r = run(t, map_args(out, more));
    EXPECT_EQ(r.status, 2) << flag << "\n" << test::describe(r);
    EXPECT_TRUE(test::has(r.err, "error: " + flag)) << r.err;
    EXPECT_FALSE(fs::exists(out)) << flag;
  }
}

// A read-only place for the report (a read-only tmpfs: CI runs as root): exit 4, nothing left.
TEST(MetalMapCommand, ReadOnlyOutputLeavesNothing) {
  TempDir t;
  const fs::path mnt = t.w() / "mnt", out = mnt / "map";
  std::string cmd = test::quoted(portalsim::test::kBinary);
  for (const std::string& a : map_args(out, {"--no-plot"})) {
    cmd += ' ';
    cmd += test::quoted(a);
  }
  const std::string listing = (t.cap() / "listing").string();
  const Result r = test::run_on_tmpfs(t.cap(), mnt, "1m", true,
                                      cmd + "; rc=$?; (cd " + test::quoted(mnt.string()) +
                                          " && find . -mindepth 1) > " + test::quoted(listing) + "; exit $rc");
  EXPECT_EQ(r.status, 4) << test::describe(r);
  EXPECT_TRUE(test::has(r.err, out.string())) << r.err;
  EXPECT_EQ(test::slurp(listing), "");
}

}  // namespace
}  // namespace portalsim
