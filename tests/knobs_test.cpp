// The knobs of plan/knobs.h are declared once: each one must reach the flags of simulate
// and generate, the spec file, the checks, the manifest and the table of
// docs/reference/knobs.md from that declaration alone.
#include "plan/knobs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <regex>

#include "base/error.h"
#include "run_binary.h"
#include "scene/scenario_list.h"
#include "schedule/run_spec.h"
#include "support.h"

namespace portalsim {
namespace embedded {
extern const std::string_view kernel_program;
}
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

// The knobs' declarations are the one list of the numbers and choices drawn per scenario
// (DrawnKnob): each element of PS_STREAM_KNOB_DRAW claimed by one declaration, and the element
// constants of the kernels' program, PS_DRAWN_<KEY>, the declared ones, by name and number.
TEST(Knobs, TheDrawnElementsAreTheDeclaredOnesAndTheKernels) {
  const std::vector<DrawnKnob>& drawn = drawn_knobs();
  ASSERT_EQ(drawn.size(), size_t{PS_DRAWN_KNOBS});
  std::map<std::string, unsigned> declared;
  for (unsigned e = 0; e < drawn.size(); ++e) {
    EXPECT_EQ(drawn[e].element, e);
    std::string name = "PS_DRAWN_" + drawn[e].key;
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    declared[name] = e;
  }
  std::map<std::string, unsigned> kernels;
  const std::string program(embedded::kernel_program);
  const std::regex define(R"(#define (PS_DRAWN_\w+) (\d+)u?\b)");
  for (auto m = std::sregex_iterator(program.begin(), program.end(), define); m != std::sregex_iterator(); ++m)
    if ((*m)[1] != "PS_DRAWN_KNOBS") kernels[(*m)[1]] = static_cast<unsigned>(std::stoul((*m)[2]));
  EXPECT_EQ(kernels, declared);
  // Two declarations of one element, or an element none declares, are refused.
  const auto refusal = [](const std::vector<Knob>& list) -> std::string {
    try {
      index_draws(list);
    } catch (const std::logic_error& e) {
      return e.what();
    }
    return "";
  };
  std::vector<Knob> twice = knobs(), none = knobs();
  for (Knob& k : twice)
    if (k.key == "netd") k.draws = find_knob("frames")->draws;
  EXPECT_EQ(refusal(twice), "knobs netd and frames both claim drawn element " + std::to_string(PS_DRAWN_FRAMES));
  for (Knob& k : none)
    if (k.key == "frames") k.draws.clear();
  EXPECT_EQ(refusal(none), "no knob declares drawn element " + std::to_string(PS_DRAWN_FRAMES));
  EXPECT_EQ(index_draws(knobs()).size(), drawn.size());
}

// The kernels' ranges (PsDrawn) follow from the declarations: each drawn number's low end is
// its field's value and its upper end the range's, or that value where fixed; the outfit's
// and the raw grid's elements, which draw no number, are 0.
TEST(Knobs, TheKernelsDrawnRangesAreTheDeclaredFieldsRanges) {
  Plan fixed, drawn;
  std::map<unsigned, std::pair<double, double>> want_fixed, want_drawn;
  for (const Knob& k : knobs()) {
    if (k.drawn >= 0) {
      const bool whole = k.kind == KnobKind::integer;
      const auto at = [&](double share) {
        const double v = k.min + (k.max - k.min) * share;
        return whole ? std::floor(v) : v;
      };
      const double a = at(0.25), b = at(0.5);
      const auto text = [&](double v) { return whole ? std::to_string(int(v)) : std::to_string(v); };
      set_knob(fixed, k, text(b), k.key);
      set_knob(drawn, k, text(a) + ".." + text(b), k.key);
      want_fixed[unsigned(k.drawn)] = {std::stod(text(b)), std::stod(text(b))};
      want_drawn[unsigned(k.drawn)] = {std::stod(text(a)), std::stod(text(b))};
    } else if (k.drawn_ends[0] >= 0) {
      set_knob(fixed, k, "300..310", k.key);
      set_knob(drawn, k, "280..290/305..306", k.key);
      want_fixed[unsigned(k.drawn_ends[0])] = {300, 300};
      want_fixed[unsigned(k.drawn_ends[1])] = {310, 310};
      want_drawn[unsigned(k.drawn_ends[0])] = {280, 290};
      want_drawn[unsigned(k.drawn_ends[1])] = {305, 306};
    }
  }
  const PsDrawn f = drawn_ranges(fixed.model), d = drawn_ranges(drawn.model);
  for (const DrawnKnob& k : drawn_knobs()) {
    SCOPED_TRACE(k.key.empty() ? "element " + std::to_string(k.element) : k.key);
    EXPECT_EQ(want_drawn.count(k.element), k.number() ? 1u : 0u);
    const auto zero = std::make_pair(0.0, 0.0);
    EXPECT_EQ(std::make_pair(f.lo[k.element], f.hi[k.element]), k.number() ? want_fixed[k.element] : zero);
    EXPECT_EQ(std::make_pair(d.lo[k.element], d.hi[k.element]), k.number() ? want_drawn[k.element] : zero);
  }
}

// A scenario list skips the columns of the drawn numbers it is given (a run's scenarios.csv
// records its draws there; the seed draws them again), and refuses them as unknown otherwise.
TEST(Knobs, AScenarioListSkipsTheDrawnNumbersColumns) {
  std::string head = "subject";
  for (int r = 1; r <= kBuiltinRegions; ++r) head += ",region" + std::to_string(r);
  const std::string text =
      head + ",netd,window_lo\n2,gun,none,none,none,none,none,none,none,none,none,none,none," + "none,1.5,291\n";
  const std::vector<Scenario> got = parse_scenario_list(test::catalogue(), text, "l.csv", nullptr, drawn_number_keys());
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].subject, 1);
  try {
    parse_scenario_list(test::catalogue(), text, "l.csv");
    ADD_FAILURE() << "a drawn number's column taken without the drawn numbers' keys";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("l.csv:1: column 15 \"netd\": unknown column"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace portalsim
