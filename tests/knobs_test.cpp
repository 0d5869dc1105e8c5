// The knobs of plan/knobs.h are declared once: each one must reach the flags of simulate
// and generate, the spec file, the checks, the manifest and the table of
// docs/reference/knobs.md from that declaration alone.
#include "plan/knobs.h"

#include <gtest/gtest.h>

#include "base/error.h"
#include "run_binary.h"
#include "schedule/run_spec.h"

namespace portalsim {
namespace {

using namespace test;

// A value other than the default, as the knob's text and as the spec file writes it.
struct Other {
  std::string text, toml;
};
Other other_value(const Knob& k, const Plan& defaults) {
  const nlohmann::json d = k.get(defaults);
  switch (k.kind) {
    case KnobKind::integer: {
      const int v = d.get<int>() == static_cast<int>(k.max) ? static_cast<int>(k.min) : static_cast<int>(k.max);
      return {std::to_string(v), std::to_string(v)};
    }
    case KnobKind::number: {  // 2.5, or the middle of a range that does not hold it
      const double v = 2.5 >= k.min && 2.5 <= k.max && d.get<double>() != 2.5 ? 2.5 : (k.min + k.max) / 2;
      return {knob_text(v), knob_text(v)};
    }
    case KnobKind::on_off:
      return d.get<bool>() ? Other{"off", "false"} : Other{"on", "true"};
    case KnobKind::grid:
      return {"16x12", "\"16x12\""};
    case KnobKind::range: {  // from the least value to the middle of the range
      const std::string t = knob_text(k.min) + ".." + knob_text((k.min + k.max) / 2);
      return {t, "\"" + t + "\""};
    }
    case KnobKind::choice:
      for (const std::string& c : k.choices)
        if (c != d.get<std::string>()) return {c, "\"" + c + "\""};
  }
  return {};
}

// Each model knob's default is written once, in its declaration: a plan made with no
// arguments holds each declared default. A fidelity knob's default is the tier's.
TEST(Knobs, EachDefaultIsItsDeclaration) {
  const Plan defaults;
  for (const Knob& k : knobs()) {
    SCOPED_TRACE(k.key);
    if (k.fidelity) {
      EXPECT_EQ(k.def, "") << "a fidelity knob's default is its tier's";
      continue;
    }
    ASSERT_FALSE(k.def.empty());
    Plan p{.model = ModelSettings(ModelSettings::Bare{}), .fidelity = {}};
    set_knob(p, k, k.def, "test");
    EXPECT_EQ(k.get(defaults), k.get(p));
    EXPECT_EQ(knob_text(k.get(defaults)), k.def) << "the declared default reads back as written";
  }
  // The thesis's values, as the golden hashes were made with them.
  const ModelSettings m;
  EXPECT_EQ(m.model, Model::thesis);
  EXPECT_EQ(m.block, 10);
  EXPECT_EQ(m.netd, 3.0);
  EXPECT_EQ(m.raw_width * 10000 + m.raw_height, 280028);
  EXPECT_EQ(m.frames, 10);
  EXPECT_TRUE(m.pattern_noise);
  EXPECT_FALSE(m.transforms());
  EXPECT_EQ(m.seed, 0u);
  EXPECT_EQ(defaults.palette, procedural::PaletteName::ironbow);
}

TEST(Knobs, EachIsASpecKeyThatSetsThePlanAndReachesTheManifest) {
  ASSERT_GE(knobs().size(), 10u);
  const Plan defaults = RunSpec{}.settings();
  for (const Knob& k : knobs()) {
    SCOPED_TRACE(k.key);
    const Other o = other_value(k, defaults);
    RunSpec spec;
    parse_spec(k.key + " = " + o.toml + "\n", "knob.toml", spec);
    const Plan p = spec.settings();
    EXPECT_EQ(knob_text(k.get(p)), o.text) << "the spec key must set the knob";
    EXPECT_NE(k.get(p), k.get(defaults));
    const nlohmann::json j = spec.to_json();
    EXPECT_EQ(j.contains(k.key), k.identity);
    if (k.identity) {
      EXPECT_EQ(j[k.key], k.get(p)) << "the manifest must record the knob's value";
    }
    // Every other knob keeps its default.
    for (const Knob& other : knobs())
      if (&other != &k) {
        EXPECT_EQ(other.get(p), other.get(defaults)) << other.key;
      }
  }
}

TEST(Knobs, BadValuesAreRefusedNamingTheFileLineAndKey) {
  for (const Knob& k : knobs()) {
    SCOPED_TRACE(k.key);
    std::vector<std::string> bad;
    if (k.kind == KnobKind::integer) bad = {"1.5", std::to_string(static_cast<long long>(k.max) + 1), "\"x\""};
    if (k.kind == KnobKind::number) bad = {"nan", "inf", "-1", "\"x\""};
    if (k.kind == KnobKind::on_off) bad = {"\"on\"", "1"};
    if (k.kind == KnobKind::choice) bad = {"\"nonsense\"", "1"};
    if (k.kind == KnobKind::range)
      bad = {"\"x\"", "\"2..1\"", "\"1..nan\"", "\"1..\"", "true", "\"" + knob_text(k.max + 1) + "\""};
    for (const std::string& v : bad) {
      RunSpec spec;
      try {
        parse_spec("count = 3\n" + k.key + " = " + v + "\n", "bad.toml", spec);
        ADD_FAILURE() << k.key << " = " << v << " was accepted";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bad.toml:2: " + k.key), std::string::npos) << e.what();
      }
    }
    Plan p;
    EXPECT_THROW(set_knob(p, k, "", k.flag()), InputError);
  }
  Plan p;
  p.model.pixel_sigma = -1;
  try {
    check_knobs(p);
    ADD_FAILURE() << "a negative sigma passed check_knobs";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--pixel-noise"), std::string::npos) << e.what();
  }
}

TEST(Knobs, EachIsAFlagOfSimulateAndGenerate) {
  TempDir t;
  for (const char* command : {"simulate", "generate"}) {
    const Result r = finish(start(t.cap(), {command, "--help"}));
    ASSERT_TRUE(r.exited && r.status == 0) << describe(r);
    for (const Knob& k : knobs()) EXPECT_NE(r.out.find(k.flag()), std::string::npos) << command << " " << k.flag();
  }
}

TEST(Knobs, TheReferenceTableIsTheDeclaredOne) {
  const std::string page = slurp(std::filesystem::path(PORTALSIM_SOURCE_DIR) / "docs/reference/knobs.md");
  const std::string table = knob_table_markdown();
  EXPECT_NE(page.find(table), std::string::npos)
      << "docs/reference/knobs.md must hold the knob table exactly as `portalsim knobs` prints it:\n"
      << table;
}

}  // namespace
}  // namespace portalsim
