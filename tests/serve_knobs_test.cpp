// The page's model settings (serve/knob_fields.h): the list the page builds its controls
// from holds every knob of the registry, and a request's fields set the plan exactly as
// the knobs' flags do.
#include <gtest/gtest.h>

#include "base/error.h"
#include "plan/knobs.h"
#include "serve/knob_fields.h"

namespace portalsim {
namespace {

using json = nlohmann::json;

TEST(ServeKnobs, ListHasEveryKnobOfTheRegistryWithItsDeclaration) {
  const json list = knob_list();
  ASSERT_EQ(list.size(), knobs().size());
  Plan standard;
  standard.fidelity = tier_fidelity(Tier::standard);
  for (size_t i = 0; i < knobs().size(); ++i) {
    const Knob& k = knobs()[i];
    const json& e = list[i];
    EXPECT_EQ(e["key"], k.key);
    EXPECT_EQ(e["flag"], k.flag());
    EXPECT_EQ(e["min"].get<double>(), k.min) << k.key;
    EXPECT_EQ(e["max"].get<double>(), k.max) << k.key;
    EXPECT_EQ(e["choices"].get<std::vector<std::string>>(), k.choices) << k.key;
    EXPECT_EQ(e["fidelity"].get<bool>(), k.fidelity) << k.key;
    EXPECT_EQ(e["drawable"].get<bool>(), k.drawn >= 0) << k.key;
    EXPECT_EQ(e["default"], knob_text(k.get(standard))) << k.key;
    EXPECT_EQ(e["help"], k.help);
    // The default, set back through the knob, is accepted and changes nothing.
    Plan p = standard;
    set_knob(p, k, e["default"].get<std::string>(), k.flag());
    EXPECT_EQ(k.get(p), k.get(standard)) << k.key;
  }
  // The kinds the page knows, and the model selector among the knobs.
  const std::map<KnobKind, std::string> kinds{{KnobKind::integer, "integer"}, {KnobKind::number, "number"},
                                              {KnobKind::on_off, "on_off"},   {KnobKind::choice, "choice"},
                                              {KnobKind::grid, "grid"},       {KnobKind::range, "range"}};
  for (size_t i = 0; i < knobs().size(); ++i) EXPECT_EQ(list[i]["kind"], kinds.at(knobs()[i].kind));
  const json* model = nullptr;
  for (const json& e : list)
    if (e["key"] == "model") model = &e;
  ASSERT_NE(model, nullptr);
  EXPECT_EQ((*model)["choices"], json({"thesis", "physics"}));
  EXPECT_EQ((*model)["default"], "thesis");
  for (const json& e : list) {
    if (e["key"] == "netd") {
      EXPECT_EQ(e["group"], "physics");
    }
  }
}

// A request's fields set each knob as its flag: the same plan as set_knob on the text.
TEST(ServeKnobs, RequestFieldsSetThePlanAsTheFlagsDo) {
  const json request{{"model", "physics"}, {"netd", "0.5"},       {"mmw_raw", "40x30"},  {"pattern_noise", false},
                     {"pixel_noise", 2.5}, {"rotate", "-10..20"}, {"precision", "fp64"}, {"subject", 3}};
  Plan got;
  got.fidelity = tier_fidelity(Tier::fast);
  apply_knobs(request, got);
  Plan want;
  want.fidelity = tier_fidelity(Tier::fast);
  for (const auto& [key, text] : std::vector<std::pair<std::string, std::string>>{{"model", "physics"},
                                                                                  {"netd", "0.5"},
                                                                                  {"mmw_raw", "40x30"},
                                                                                  {"pattern_noise", "off"},
                                                                                  {"pixel_noise", "2.5"},
                                                                                  {"rotate", "-10..20"},
                                                                                  {"precision", "fp64"}})
    set_knob(want, *find_knob(key), text, "x");
  for (const Knob& k : knobs()) EXPECT_EQ(k.get(got), k.get(want)) << k.key;
  EXPECT_EQ(got.model.model, Model::physics);
  EXPECT_EQ(got.model.raw_width, 40);
  // A knob the request leaves out keeps the tier's value.
  EXPECT_EQ(got.fidelity.pooling, tier_fidelity(Tier::fast).pooling);
}

TEST(ServeKnobs, BadFieldsNameTheFlag) {
  const std::vector<std::pair<json, std::string>> cases{{{{"model", "quantum"}}, "--model"},
                                                        {{{"netd", "-1"}}, "--netd"},
                                                        {{{"netd", 1000}}, "--netd"},
                                                        {{{"mmw_raw", "28"}}, "--mmw-raw"},
                                                        {{{"netd", json::array()}}, "\"netd\""},
                                                        {{{"pattern_noise", "maybe"}}, "--pattern-noise"},
                                                        {{{"metal_noise", 2.5}}, "--metal-noise"}};
  for (const auto& [request, want] : cases) {
    Plan p;
    try {
      apply_knobs(request, p);
      ADD_FAILURE() << "accepted " << request.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace portalsim
