// The default catalogue's contents, object names and the threat rules.
#include <gtest/gtest.h>

#include <algorithm>

#include "backend/compare.h"
#include "backend/opencl/physics_params.h"
#include "backend/stages.h"
#include "base/error.h"
#include "plan/knobs.h"
#include "scene/camera_kind.h"
#include "scene/rules.h"
#include "support.h"

namespace portalsim {
namespace {

using test::catalogue;

TEST(Catalogue, DefaultHoldsTheThesisInventory) {
  const Catalogue& c = catalogue();
  EXPECT_EQ(c.subjects.size(), 5u);
  EXPECT_EQ(c.objects.size(), 31u);  // the thesis's 12 first, then docs/model/objects.md's
  EXPECT_EQ(c.noise.size(), 5u);
  EXPECT_EQ(c.metal_categories.size(), 6u);
  EXPECT_EQ(c.influence.size(), 6u);
  int upper = 0;
  for (int r = 0; r < kBuiltinRegions; ++r) upper += c.sensors[0].sees(r);
  EXPECT_EQ(upper, 6);
  EXPECT_EQ(c.regions[2].name, "left-chest");
  EXPECT_EQ(c.regions[3].name, "right-abdomen");
  EXPECT_EQ(c.region_count(), kBuiltinRegions);
  EXPECT_EQ(c.zones, kBuiltinZones);
  EXPECT_EQ(c.subjects[0].base_zones, std::vector<int>(kBuiltinZones, 200));
  // Of the thesis's 12, gun and rod have horizontal and vertical drawings; the rest one.
  for (size_t k = 0; k < 12; ++k) {
    const Object& o = c.objects[k];
    const bool two = o.name == "gun" || o.name == "iron-rod";
    EXPECT_EQ(o.variants.size(), two ? 2u : 1u) << o.name;
  }
}

// A subject's base image files go to the views that name them, and to no other: a view it
// names no file for is the procedural body.
TEST(Catalogue, SubjectImagesGoOnlyToTheirOwnViews) {
  Subject s;
  s.images.emplace("ir", ImageSource{"/data/ir.png", "catalogue.toml:3: subjects[1].images.ir"});
  EXPECT_EQ(s.image("ir").path, "/data/ir.png");
  EXPECT_EQ(s.image("upper").path, "");
  EXPECT_EQ(s.image("lower").path, "");
  EXPECT_EQ(s.image("back").path, "");
}

TEST(Catalogue, NamesIgnoreCaseAndPunctuationAndAcceptThesisSpellings) {
  const Catalogue& c = catalogue();
  EXPECT_EQ(c.find_object("Gun"), c.find_object("gun"));
  EXPECT_EQ(c.objects[c.find_object("Rod")].name, "iron-rod");
  EXPECT_EQ(c.objects[c.find_object("Mobile")].name, "mobile-phone");
  EXPECT_EQ(c.objects[c.find_object("Metal Barrel")].name, "iron-pipe");
  EXPECT_EQ(c.objects[c.find_object("iron_pipe")].name, "iron-pipe");
  EXPECT_EQ(c.objects[c.find_object("Compact Disk")].name, "compact-disk");
  EXPECT_EQ(c.find_object("flamethrower"), -1);
  EXPECT_EQ(c.find_object(""), -1);
}

TEST(Catalogue, ObjectTokens) {
  const Catalogue& c = catalogue();
  const int16_t gv = parse_object_token(c, "gun:v", "t");
  EXPECT_EQ(c.variant_name(gv), "gun:v");
  EXPECT_EQ(c.variant_name(parse_object_token(c, "GUN:Vertical", "t")), "gun:v");
  EXPECT_EQ(c.variant_name(parse_object_token(c, "gun", "t")), "gun:h");
  EXPECT_EQ(parse_object_token(c, "None", "t"), kNoObject);
  EXPECT_THROW(parse_object_token(c, "gun:x", "t"), InputError);
  EXPECT_THROW(parse_object_token(c, "disk:v", "t"), InputError);
  EXPECT_THROW(parse_object_token(c, "none:v", "t"), InputError);
  const Scenario s = parse_object_list(c, {"none", "none", "gun"});
  EXPECT_EQ(s.objects[2], parse_object_token(c, "gun", "t"));
  for (int r = 3; r < kBuiltinRegions; ++r) EXPECT_EQ(s.objects[r], kNoObject);
  EXPECT_THROW(parse_object_list(c, std::vector<std::string>(14, "none")), InputError);
  try {
    parse_object_list(c, {"none", "none", "bazooka"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("region 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bazooka"), std::string::npos) << e.what();
  }
}

TEST(Rules, ThesisCasesAndCombinations) {
  const Catalogue& c = catalogue();
  const auto scene = [&](std::vector<std::string> objs) { return parse_object_list(c, objs); };
  const ThreatRule gun(c, "gun");
  EXPECT_TRUE(gun(scene({"none", "gun:v"})));
  EXPECT_FALSE(gun(scene({"iron-rod", "metal-plate"})));
  const ThreatRule both(c, "iron-rod&metal-plate");
  EXPECT_TRUE(both(scene({"rod:v", "none", "none", "none", "none", "none", "plate"})));
  EXPECT_FALSE(both(scene({"rod"})));
  EXPECT_FALSE(both(scene({"plate"})));
  const ThreatRule either(c, "gun | iron-rod & metal-plate");
  EXPECT_TRUE(either(scene({"gun"})));
  EXPECT_TRUE(either(scene({"rod", "plate"})));
  EXPECT_FALSE(either(scene({"rod", "disk"})));
  const ThreatRule vertical(c, "gun:v & !(metal-plate)");
  EXPECT_TRUE(vertical(scene({"gun:v"})));
  EXPECT_FALSE(vertical(scene({"gun:h"})));
  EXPECT_FALSE(vertical(scene({"gun:v", "plate"})));
  for (const char* bad : {"", "gun &", "gun | | rod", "(gun", "gun)", "laser", "none", "gun:q"})
    EXPECT_THROW(ThreatRule(c, bad), InputError) << bad;
  // Nesting: 64 levels parse; 65, and a 100000-deep nest, are refused instead of overflowing the stack.
  auto nest = [](int n, const std::string& open, const std::string& close) {
    std::string r;
    for (int i = 0; i < n; ++i) r += open;
    r += "gun";
    for (int i = 0; i < n; ++i) r += close;
    return r;
  };
  EXPECT_TRUE(ThreatRule(c, nest(kMaxRuleDepth, "(", ")"))(scene({"gun"})));
  EXPECT_TRUE(ThreatRule(c, nest(kMaxRuleDepth, "!", ""))(scene({"gun"})));  // 64 negations
  for (const std::string& deep : {nest(kMaxRuleDepth + 1, "(", ")"), nest(kMaxRuleDepth + 1, "!", ""),
                                  nest(100000, "(", ")"), nest(100000, "!(", ")")})
    EXPECT_THROW(ThreatRule(c, deep), InputError) << deep.size();
}

// Each camera kind is listed at its Camera's index, under a name of its own, so that a
// view's camera and its name in the catalogue find the same kind.
TEST(CameraKinds, ListedInCameraOrderUnderDistinctNames) {
  const std::vector<const CameraKind*>& kinds = camera_kinds();
  for (size_t k = 0; k < kinds.size(); ++k) {
    SCOPED_TRACE(kinds[k]->name);
    EXPECT_EQ(static_cast<size_t>(kinds[k]->camera), k);
    EXPECT_EQ(camera_kind_named(kinds[k]->name), kinds[k]);
    EXPECT_EQ(&camera_kind(kinds[k]->camera), kinds[k]);
  }
  EXPECT_EQ(camera_kind_names(), "\"mmw\" or \"ir\"");
  EXPECT_EQ(camera_kind_named("thermal"), nullptr);
}

// Each kind answers every question code asks of it, so a new kind's declaration is whole
// where its answers name something: a NETD knob whose bound is the kind's, registered
// stages, a physics fill step; and the catalogue and the comparisons hold a slot per kind.
TEST(CameraKinds, EachAnswersEveryQuestion) {
  const Catalogue& c = catalogue();
  const OutputDiff diff;
  EXPECT_EQ(diff.cameras.size(), camera_kinds().size());
  for (const CameraKind* kind : camera_kinds()) {
    SCOPED_TRACE(kind->name);
    ASSERT_NE(kind->label, nullptr);
    EXPECT_STRNE(kind->label, "");
    for (const char* noun : kind->nouns) EXPECT_NE(noun, nullptr);
    // Its NETD knob is a number knob bounded as a view's own netd is.
    const DrawnKnob& netd = drawn_knobs().at(kind->netd_knob);
    EXPECT_NE(std::get_if<double ModelSettings::*>(&netd.field), nullptr);
    ASSERT_NE(find_knob(netd.key), nullptr);
    EXPECT_EQ(find_knob(netd.key)->max, kind->netd_max);
    for (const std::string& stage : kind->physics_chain) EXPECT_NO_THROW(view_stage(stage)) << stage;
    EXPECT_TRUE(opencl::has_physics_fill(*kind)) << kind->physics_fill;
    for (const Object& o : c.objects) {
      EXPECT_EQ(o.levels.size(), camera_kinds().size()) << o.name;
      for (const Variant& v : o.variants) EXPECT_EQ(v.images.size(), camera_kinds().size()) << o.name;
    }
  }
  // Two kinds told apart in messages.
  for (const CameraKind* a : camera_kinds())
    for (const CameraKind* b : camera_kinds())
      if (a != b) {
        EXPECT_STRNE(a->label, b->label);
      }
}

// A view's own netd replaces its kind's NETD knob, and only that one, for the view's launch.
TEST(CameraKinds, OwnNetdReplacesTheKindsKnob) {
  for (const CameraKind* kind : camera_kinds()) {
    SCOPED_TRACE(kind->name);
    ModelSettings run;
    for (DrawnRange& d : run.drawn) d = {.lo = 0.0, .hi = 0.01};
    Sensor view;
    view.camera = kind->camera;
    view.netd = 0.005;
    const ModelSettings m = run.for_view(view);
    for (unsigned e = 0; e < PS_DRAWN_KNOBS; ++e) {
      const auto* field = std::get_if<double ModelSettings::*>(&drawn_knobs().at(e).field);
      SCOPED_TRACE(drawn_knobs().at(e).key);
      EXPECT_EQ(m.drawn[e].varies(), e != kind->netd_knob);
      if (field) {
        EXPECT_EQ(m.**field, e == kind->netd_knob ? 0.005 : run.**field);
      }
    }
  }
}

}  // namespace
}  // namespace portalsim
