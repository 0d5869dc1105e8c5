// The physics model's IR camera (--model physics): parity of its kernels with the fp64
// reference, and the invariants that fail when its physics is wrong: the contact shadow
// fades with the time worn, heat spreading widens the shadow's edge, the noise through the
// display is ir_netd; the palette changes the RGB but never the index; bad values refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "assets/image_io.h"
#include "backend/compare.h"
#include "backend/reference/stages.h"
#include "backend/stages.h"
#include "base/embedded.h"
#include "base/error.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;
using test::physics_plan;
using test::variant_of;

int ir_view(const Catalogue& cat) { return cat.sensor_index("ir"); }

using Edits = std::vector<std::pair<std::string, std::string>>;

// The default catalogue with edits (each `from` must occur), and its assets.
struct World {
  Catalogue cat;
  AssetSet assets;
  explicit World(const Edits& edits = {}) {
    std::string text(embedded::default_catalogue);
    for (const auto& [from, to] : edits) {
      const size_t at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) text.replace(at, from.size(), to);
    }
    cat = parse_catalogue(text, "ir.toml", "", "");
    assets = build_assets(cat);
  }
};

// A scenario with one object in region 2 (the chest), and where its IR sprite's centre lies.
struct OneObject {
  Scenario scene;
  int cx = 0, cy = 0;
  OneObject(const World& w, const std::string& object) {
    scene.objects[1] = static_cast<int16_t>(variant_of(w.cat, object));
    const reference::ViewScene vs = reference::view_scene(w.cat, w.assets, ModelSettings{}, ir_view(w.cat), scene, 0);
    EXPECT_EQ(vs.placed.size(), 1u);
    const reference::Placed& p = vs.placed.at(0);
    cx = p.x0 + p.sprite->width / 2;
    cy = p.y0 + p.sprite->height / 2;
  }
};

// The reference's IR field through the named stages.
reference::Field ir_field(const World& w, const ModelSettings& m, const Scenario& s,
                          const std::vector<std::string>& stages) {
  const reference::ViewScene vs = reference::view_scene(w.cat, w.assets, m, ir_view(w.cat), s, 0);
  reference::Field f;
  for (const std::string& stage : stages) view_stage(stage).reference(vs, f);
  return f;
}

TEST(IrPhysics, TheIrViewRunsItsOwnPhysicsChain) {
  const Sensor& ir = catalogue().sensors[ir_view(catalogue())];
  EXPECT_EQ(ir.physics_chain,
            (std::vector<std::string>{"contact_shadow", "heat_spread", "ir_surface", "ir_netd", "ir_display"}));
  EXPECT_EQ(ir.chain, (std::vector<std::string>{"composite", "pattern_noise", "sensor_noise", "display"}));
  // The procedural subjects' trunk (ir_core about 215) reads as skin, the background (35) as the room.
  const PhysicsConfig& pc = catalogue().physics;
  const double per_index = (pc.ir_index_max_k - pc.ir_index_min_k) / 255;
  EXPECT_NEAR(pc.ir_index_min_k + 215 * per_index, pc.skin_temperature, 0.1);
  EXPECT_NEAR(pc.ir_index_min_k + 35 * per_index, pc.room_temperature, 0.1);
}

TEST(IrPhysics, KernelsMatchTheReferenceInEveryTier) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < 48; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes);
  const World wide(Edits{{"ir_spread_mm = 10.0", "ir_spread_mm = 40.0"}});
  const World sharp(Edits{{"ir_spread_mm = 10.0", "ir_spread_mm = 0.0"}});
  struct Case {
    const char* name;
    const World* world;
    Tier tier;
    double jitter;
    bool bilinear;
    double worn;
  };
  const World plain;
  for (const Case& c :
       {Case{"standard", &plain, Tier::standard, 0, false, 5}, Case{"exact", &plain, Tier::exact, 0, false, 5},
        Case{"fast", &plain, Tier::fast, 0, false, 5}, Case{"jitter", &plain, Tier::standard, 6, false, 5},
        Case{"bilinear", &plain, Tier::standard, 6, true, 5}, Case{"bilinear fp64", &plain, Tier::exact, 6, true, 0},
        Case{"spread 40 mm", &wide, Tier::standard, 0, false, 0}, Case{"no spread", &sharp, Tier::fast, 3, true, 2}}) {
    SCOPED_TRACE(c.name);
    Plan plan = physics_plan();
    plan.fidelity = tier_fidelity(c.tier);
    plan.model.jitter = c.jitter;
    plan.model.bilinear = c.bilinear;
    plan.model.worn_minutes = c.worn;
    BatchOutput r, k;
    make_reference_backend(c.world->cat, c.world->assets)->run(batch, plan, r);
    make_opencl_backend(c.world->cat, c.world->assets, test::runtime())->run(batch, plan, k);
    const OutputDiff d = compare_outputs(k, r);
    // Stated tolerance: IR pixels (temperature index) within 1 level, at most 0.5% off by one.
    EXPECT_GT(d.of(Camera::ir).pixels, 0u);
    test::expect_camera_parity(d.of(Camera::ir));
  }
}

// The declared fast path (contact_shadow -> heat_spread -> ir_surface in
// ir_surface_fused; with only ir_display after it, ir_surface_display_fused; with ir_netd
// then ir_display, ir_surface_noise_display_fused) against the chain of stage kernels:
// the same bits in every tier, -cl-fast-relaxed-math too (the fast path writes each sum
// in the stage kernels' form). Integer, bilinear and randomised placement, objects over
// the view's edges, no, the default and a wide heat spread, IR NETD 0 (the display fused)
// and 0.05 K (noise and display fused).
TEST(IrPhysics, FastPathMatchesTheChainOfStageKernels) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < 32; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  scenes.push_back(Scenario{});  // no object: no shadow at all
  const SceneBatch batch = test::batch_of(scenes);
  const World plain, wide(Edits{{"ir_spread_mm = 10.0", "ir_spread_mm = 40.0"}}),
      sharp(Edits{{"ir_spread_mm = 10.0", "ir_spread_mm = 0.0"}});
  struct Place {
    const char* name;
    bool bilinear;
    double jitter, rotate, scale;
  };
  size_t shadowed = 0;
  for (const World* w : {&plain, &wide, &sharp}) {
    auto cl = make_opencl_backend(w->cat, w->assets, test::runtime());
    for (Tier tier : {Tier::fast, Tier::standard, Tier::exact})
      for (const Place& place : {Place{"integer", false, 0, 0, 1}, Place{"bilinear", true, 5, 0, 1},
                                 Place{"over the edges", false, 60, 0, 1}, Place{"randomised", false, 4, 30, 1.4}})
        for (double netd : {0.0, 0.05}) {
          SCOPED_TRACE(std::string(tier_name(tier)) + " " + place.name + " spread " +
                       std::to_string(w->cat.physics.ir_spread_mm) + " netd " + std::to_string(netd));
          Plan plan = physics_plan(3);
          plan.images = 1u << ir_view(w->cat);
          plan.features = false;
          plan.metal = false;
          plan.fidelity = tier_fidelity(tier);
          plan.model.bilinear = place.bilinear;
          plan.model.jitter = place.jitter;
          plan.model.rotate_lo = -place.rotate;
          plan.model.rotate_hi = place.rotate;
          plan.model.scale_hi = place.scale;
          plan.model.worn_minutes = 0;
          plan.model.ir_netd = netd;
          BatchOutput fast, staged, bare;
          cl->run(batch, plan, fast);
          plan.fidelity.fused = false;
          cl->run(batch, plan, staged);
          const std::vector<uint8_t>& a = fast.view("ir").pixels;
          const std::vector<uint8_t>& b = staged.view("ir").pixels;
          ASSERT_EQ(a.size(), b.size());
          EXPECT_EQ(a, b);
          // The shadow shows: the path has something to get wrong.
          plan.model.worn_minutes = 1440;
          cl->run(batch, plan, bare);
          for (size_t k = 0; k < a.size(); ++k) shadowed += std::abs(int(a[k]) - int(bare.view("ir").pixels[k])) > 3;
        }
  }
  EXPECT_GT(shadowed, 50000u);
}

// Each stage that changes the image changes it in both backends alike; the model switches
// the IR view too, while the thesis chain stays what it was.
TEST(IrPhysics, EachStageOfTheChainDoesSomethingInBothBackends) {
  std::vector<Scenario> scenes;
  for (size_t k = 0; k < 16; ++k) scenes.push_back(test::random_scenario(catalogue(), k, 6));
  const SceneBatch batch = test::batch_of(scenes);
  const Plan plan = physics_plan();
  BatchOutput whole, thesis;
  make_reference_backend(catalogue(), assets())->run(batch, plan, whole);
  make_reference_backend(catalogue(), assets())->run(batch, Plan{}, thesis);
  EXPECT_NE(whole.view("ir").pixels, thesis.view("ir").pixels);
  for (const std::string dropped : {"heat_spread", "ir_netd"}) {
    SCOPED_TRACE(dropped);
    Catalogue cat = catalogue();
    std::erase(cat.sensors[ir_view(cat)].physics_chain, dropped);
    BatchOutput r, k;
    make_reference_backend(cat, assets())->run(batch, plan, r);
    make_opencl_backend(cat, assets(), test::runtime())->run(batch, plan, k);
    EXPECT_LE(compare_outputs(k, r).of(Camera::ir).max_abs, 1);
    EXPECT_NE(r.view("ir").pixels, whole.view("ir").pixels) << "the stage changes nothing";
    EXPECT_EQ(r.view("upper").pixels, whole.view("upper").pixels) << "an IR stage changed the MMW view";
  }
}

// The shadow over an object is -coupling (skin - T_object(t)): it fades monotonically as
// the object warms, and is gone after a day, in the reference (kelvin) and in the kernels'
// displayed index.
TEST(IrPhysics, ContrastFadesWithTheTimeWorn) {
  const World w;
  const PhysicsConfig& pc = w.cat.physics;
  auto cl = make_opencl_backend(w.cat, w.assets, test::runtime());
  const double scale = 255.0 / (pc.ir_display_max - pc.ir_display_min);
  for (const char* object : {"metal-plate", "ceramic-plate", "cement-tile"}) {
    SCOPED_TRACE(object);
    ASSERT_GE(w.cat.find_object(object), 0);
    const OneObject one(w, object);
    const Scenario bare;
    const Material& mat = w.cat.materials.at(w.cat.objects[w.cat.find_object(object)].material_id);
    double last_k = -1e9;
    int last_level = -1000;
    for (double worn : {0.0, 1.0, 3.0, 10.0, 30.0, 60.0, 240.0, 1440.0}) {
      SCOPED_TRACE(worn);
      Plan plan = physics_plan();
      plan.model.worn_minutes = worn;
      plan.model.ir_netd = 0;
      // Reference: the shadow field at the object's centre, in kelvin, against the formula.
      const reference::Field shadow = ir_field(w, plan.model, one.scene, {"contact_shadow", "heat_spread"});
      const double t_object =
          pc.skin_temperature - (pc.skin_temperature - pc.room_temperature) * std::exp(-worn / mat.warm_minutes);
      const double expected = -pc.ir_coupling * (pc.skin_temperature - t_object);
      const double centre = shadow.at(one.cx, one.cy);
      EXPECT_NEAR(centre, expected, 0.02 * std::abs(expected) + 1e-9);
      EXPECT_GT(centre, last_k) << "the shadow must fade as the object warms";
      last_k = centre;
      // Kernels: the displayed index at the centre, with and without the object.
      BatchOutput a, b;
      cl->run(test::batch_of({one.scene}), plan, a);
      cl->run(test::batch_of({bare}), plan, b);
      const size_t at = static_cast<size_t>(one.cy) * a.view("ir").width + one.cx;
      const int seen = int(a.view("ir").pixels[at]) - int(b.view("ir").pixels[at]);
      EXPECT_NEAR(seen, centre * scale, 1.0);
      EXPECT_GE(seen, last_level) << "the displayed contrast must not grow with time worn";
      last_level = seen;
      if (worn == 0.0 && std::string(object) == "metal-plate") {
        EXPECT_LT(seen, -50) << "a cold plate shows clearly";
      }
      if (worn == 1440.0) {
        EXPECT_LT(std::abs(centre), 1e-6) << "worn a day, the object is at skin temperature";
        EXPECT_EQ(a.view("ir").pixels, b.view("ir").pixels);
      }
    }
  }
}

// Where an object reaches past the body's outline (the gun's grip, drawn horizontally at the
// right abdomen), its shadow is taken against the room it touches there, not the skin:
// -coupling (room - T_object), never colder than the room, where it was 10 K below it
// (palette index 0 beside the body). On the body it stays against the skin.
TEST(IrPhysics, AnObjectPastTheBodysOutlineIsShadowedAgainstTheRoom) {
  const World w;
  const PhysicsConfig& pc = w.cat.physics;
  Scenario scene;
  int region = -1;
  for (int r = 0; r < kBuiltinRegions; ++r)
    if (w.cat.regions[r].name == "right-abdomen") region = r;
  ASSERT_GE(region, 0);
  scene.objects[region] = static_cast<int16_t>(variant_of(w.cat, "gun"));
  Plan plan = physics_plan();
  plan.model.ir_netd = 0;
  const int gun = variant_of(w.cat, "gun");
  const Material& mat = w.cat.materials.at(w.cat.object_of(gun).material_id);
  const double t_object = pc.skin_temperature - (pc.skin_temperature - pc.room_temperature) *
                                                    std::exp(-plan.model.worn_minutes / mat.warm_minutes);
  const double on_body = -pc.ir_coupling * (pc.skin_temperature - t_object);
  const double off_body = -pc.ir_coupling * (pc.room_temperature - t_object);
  ASSERT_GE(off_body, 0.0);

  // Reference, before the heat spreads: each covered pixel between 0 and its surface's dT.
  const reference::Field shadow = ir_field(w, plan.model, scene, {"contact_shadow"});
  const Image& base = w.assets.bases[0][ir_view(w.cat)];
  const double per_index = (pc.ir_index_max_k - pc.ir_index_min_k) / 255.0;
  const auto is_body = [&](int x, int y) {
    return pc.ir_index_min_k + per_index * base.at(x, y) >= (pc.room_temperature + pc.skin_temperature) / 2;
  };
  int off_covered = 0, off_full = 0, on_full = 0;
  for (int y = 0; y < shadow.height; ++y)
    for (int x = 0; x < shadow.width; ++x) {
      const double v = shadow.at(x, y);
      if (v == 0) continue;
      if (is_body(x, y)) {
        EXPECT_LE(v, 0.0);
        EXPECT_GE(v, on_body - 1e-9);
        on_full += std::abs(v - on_body) < 1e-9;
      } else {
        ++off_covered;
        EXPECT_GE(v, 0.0) << x << "," << y;
        EXPECT_LE(v, off_body + 1e-9);
        off_full += std::abs(v - off_body) < 1e-9;
      }
    }
  EXPECT_GT(off_covered, 20) << "the grip must reach past the outline for this test to mean anything";
  EXPECT_GT(off_full, 0);
  EXPECT_GT(on_full, 0);

  // Kernels, as shown: off the body and not touching it (where the skin's shadow spreads
  // over), the gun never shows below the bare room beside the body; it was index 0 there.
  auto cl = make_opencl_backend(w.cat, w.assets, test::runtime());
  BatchOutput with, bare;
  cl->run(test::batch_of({scene}), plan, with);
  cl->run(test::batch_of({Scenario{}}), plan, bare);
  const ViewImages& a = with.view("ir");
  const ViewImages& b = bare.view("ir");
  int compared = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (shadow.at(x, y) == 0) continue;
      bool near_body = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = std::clamp(x + dx, 0, a.width - 1), t = std::clamp(y + dy, 0, a.height - 1);
          near_body = near_body || is_body(u, t);
        }
      if (near_body) continue;
      const size_t at = static_cast<size_t>(y) * a.width + x;
      EXPECT_GE(a.pixels[at], b.pixels[at]) << x << "," << y;
      ++compared;
    }
  EXPECT_GT(compared, 0);
}

// The 10%-90% width of the shadow's left edge along the row through the object's centre,
// in pixels (linear between pixels).
double edge_width(const reference::Field& f, int cx, int cy) {
  const double floor_v = f.at(cx, cy);  // the shadow is negative; 0 far away
  const auto crossing = [&](double share) {
    const double level = share * floor_v;
    for (int x = cx; x > 0; --x)
      if (f.at(x - 1, cy) > level) {  // f(x) <= level < f(x - 1)
        const double a = f.at(x - 1, cy), b = f.at(x, cy);
        return (x - 1) + (a - level) / (a - b);
      }
    return 0.0;
  };
  return crossing(0.9) - crossing(0.1);  // 90% lies nearer the centre
}

// More heat spreading in the fabric widens the shadow's edge, as a Gaussian of
// ir_spread_mm would: 10%-90% width sqrt(w0^2 + (2.563 sigma)^2) within 10%.
TEST(IrPhysics, MoreSpreadingWidensTheShadowsEdge) {
  const std::pair<std::string, std::string> big{"shape = \"plate\"\nsize = [32, 40]",
                                                "shape = \"plate\"\nsize = [120, 120]"};
  Plan plan = physics_plan();
  plan.model.worn_minutes = 0;
  double w0 = 0, last = 0;
  for (double mm : {0.0, 10.0, 25.0, 40.0}) {
    SCOPED_TRACE(mm);
    // The plate is wider than the body; a room colder than the IR scale's bottom makes every
    // pixel body (contact_shadow), so that its whole edge is shadowed against the skin.
    const World w(Edits{big,
                        {"ir_spread_mm = 10.0", "ir_spread_mm = " + std::to_string(mm)},
                        {"room_temperature = 293.0", "room_temperature = 270.0"}});
    const OneObject one(w, "metal-plate");
    const reference::Field f = ir_field(w, plan.model, one.scene, {"contact_shadow", "heat_spread"});
    const double width = edge_width(f, one.cx, one.cy);
    const double sigma = reference::ir_spread_pixels(w.cat, w.cat.sensors[ir_view(w.cat)]);
    RecordProperty("edge_" + std::to_string(int(mm)) + "mm", std::to_string(width));
    if (mm == 0) {
      w0 = width;
      EXPECT_LT(width, 2.0) << "the sprite's own edge is sharp";
    } else {
      EXPECT_GT(width, last);
      EXPECT_NEAR(width, std::hypot(w0, 2.5631 * sigma), 0.1 * width);
    }
    last = width;
  }
}

// Two seeds on the same scene differ by the noise alone: their variance is ir_netd through
// the display window, plus the rounding's 1/12 level^2 per image, within 5%.
TEST(IrPhysics, NoiseMatchesTheIrNetdThroughTheDisplay) {
  const Catalogue& cat = catalogue();
  auto cl = make_opencl_backend(cat, assets(), test::runtime());
  const std::vector<Scenario> scene(1, test::random_scenario(cat, 3, 3));
  const double scale = 255.0 / (cat.physics.ir_display_max - cat.physics.ir_display_min);
  for (double netd : {0.05, 0.3}) {
    SCOPED_TRACE(netd);
    BatchOutput a, b;
    Plan plan = physics_plan(100);
    if (netd != 0.05) plan.model.ir_netd = netd;  // 0.05 is the default
    cl->run(test::batch_of(scene), plan, a);
    plan.model.seed = 101;
    cl->run(test::batch_of(scene), plan, b);
    const ViewImages& va = a.view("ir");
    const ViewImages& vb = b.view("ir");
    double measured = 0, expected = 0;
    for (size_t k = 0; k < va.pixels.size(); ++k) {
      const int p = va.pixels[k], q = vb.pixels[k];
      if (p == 0 || p == 255 || q == 0 || q == 255) continue;  // clamped
      measured += (p - q) * (p - q) / 2.0;
      expected += scale * scale * netd * netd + 1.0 / 12;
    }
    EXPECT_GT(expected, 0.9 * (1.0 / 12 + scale * scale * netd * netd) * va.pixels.size()) << "too many clamped";
    EXPECT_NEAR(measured / expected, 1.0, 0.05);
  }
  // NETD 0: the seed changes nothing.
  BatchOutput a, b;
  Plan quiet = physics_plan(1);
  quiet.model.ir_netd = 0;
  cl->run(test::batch_of(scene), quiet, a);
  quiet.model.seed = 2;
  cl->run(test::batch_of(scene), quiet, b);
  EXPECT_EQ(a.view("ir").pixels, b.view("ir").pixels);
}

// --palette changes ir.png's colours, never the index: the gray image is the index, and
// the default (ironbow) image reads back to the same index; the MMW views are untouched.
TEST(IrPhysics, PaletteChangesTheRgbNotTheIndex) {
  EXPECT_NE(procedural::ir_palette(procedural::PaletteName::gray), procedural::ir_palette());
  EXPECT_NE(procedural::ir_palette(procedural::PaletteName::rainbow), procedural::ir_palette());
  for (int i = 0; i < 256; ++i)
    EXPECT_EQ(procedural::ir_palette(procedural::PaletteName::gray)[i],
              (std::array<uint8_t, 3>{uint8_t(i), uint8_t(i), uint8_t(i)}));
  test::TempDir t;
  for (const char* model : {"thesis", "physics"}) {
    SCOPED_TRACE(model);
    std::map<std::string, Image> ir, upper;
    for (const char* palette : {"ironbow", "gray", "rainbow"}) {
      const std::filesystem::path out = t.w() / (std::string(model) + palette);
      const test::Result r = test::finish(test::start(t.cap(), {"simulate", "none", "gun", "none", "phone", "--model",
                                                                model, "--palette", palette, "--out", out.string()}));
      ASSERT_EQ(r.status, 0) << test::describe(r);
      ir[palette] = read_image((out / "ir.png").string(), "ir.png");
      upper[palette] = read_image((out / "upper.png").string(), "upper.png");
    }
    EXPECT_EQ(upper["gray"].pixels, upper["ironbow"].pixels);
    EXPECT_NE(ir["gray"].pixels, ir["ironbow"].pixels);
    EXPECT_NE(ir["rainbow"].pixels, ir["ironbow"].pixels);
    const Image index = to_temperature(ir["ironbow"], procedural::ir_palette(), false);
    const Image& gray = ir["gray"];
    ASSERT_EQ(gray.channels, 3);
    size_t same = 0;
    for (size_t k = 0; k < index.pixels.size(); ++k) same += index.pixels[k] == gray.pixels[k * 3];
    // Ironbow's neighbouring entries can be equal colours; read back, they give the first.
    EXPECT_GE(same, index.pixels.size() * 99 / 100);
  }
}

TEST(IrPhysics, BadValuesAreRefused) {
  Plan q;
  const Knob& netd = *find_knob("ir_netd");
  for (const char* bad : {"-0.1", "10.5", "nan", "inf", "x", "", "0.05K"})
    EXPECT_THROW(set_knob(q, netd, bad, "--ir-netd"), InputError) << bad;
  set_knob(q, netd, "0.2", "--ir-netd");
  EXPECT_EQ(q.model.ir_netd, 0.2);
  const Knob& palette = *find_knob("palette");
  for (const char* bad : {"jet", "Ironbow", "", "gray "})
    EXPECT_THROW(set_knob(q, palette, bad, "--palette"), InputError) << bad;
  set_knob(q, palette, "rainbow", "--palette");
  EXPECT_EQ(q.palette, procedural::PaletteName::rainbow);
  struct Bad {
    const char* from;
    const char* to;
    const char* field;
  };
  for (const Bad& b : {Bad{"ir_coupling = 0.8", "ir_coupling = 1.5", "physics.ir_coupling"},
                       Bad{"ir_spread_mm = 10.0", "ir_spread_mm = -1.0", "physics.ir_spread_mm"},
                       Bad{"ir_spread_mm = 10.0", "ir_spread_mm = nan", "physics.ir_spread_mm"},
                       Bad{"ir_display_max = 308.9", "ir_display_max = 290.0", "physics.ir_display_max"},
                       Bad{"ir_index_max_k = 308.9", "ir_index_max_k = 280.0", "physics.ir_index_max_k"},
                       Bad{"ir_index_min_k = 290.5", "ir_index_min_k = \"cold\"", "physics.ir_index_min_k"},
                       Bad{"ir_coupling = 0.8", "ir_coupling = 0.8\nir_couplng = 0.5", "ir_couplng"}}) {
    SCOPED_TRACE(b.to);
    std::string text(embedded::default_catalogue);
    const size_t at = text.find(b.from);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, std::strlen(b.from), b.to);
    try {
      parse_catalogue(text, "bad.toml", "", "");
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.toml:"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(b.field), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace portalsim
