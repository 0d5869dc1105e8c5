// The catalogue's objects beyond the thesis's 12 (docs/model/objects.md): classes and
// families that pools and rules name, the default pool that keeps a run without --pool on
// the thesis's objects, the metal each kind carries, and bad entries refused.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "backend/compare.h"
#include "base/error.h"
#include "parity_support.h"
#include "plan/tolerance.h"
#include "run_binary.h"
#include "scene/generator.h"
#include "scene/rules.h"
#include "schedule/run_spec.h"
#include "support.h"

namespace portalsim {
namespace {

namespace fs = std::filesystem;
using test::catalogue;

std::set<std::string> names_of(const Catalogue& cat, const std::vector<int>& objects) {
  std::set<std::string> s;
  for (int o : objects) s.insert(cat.objects[o].name);
  return s;
}

// What `n` scenarios drawn from `pool` (up to 4 objects each) carry.
std::set<std::string> drawn(const std::vector<int>& pool, int n = 3000) {
  GeneratorSpec spec;
  spec.pool = pool;
  const Generator gen(catalogue(), spec, 21);
  std::set<std::string> seen;
  for (int i = 0; i < n; ++i)
    for (int16_t v : gen(i).objects)
      if (v != kNoObject) seen.insert(catalogue().object_of(v).name);
  return seen;
}

TEST(Objects, EveryBuiltInObjectHasAClassAndTheFamiliesTheirSizes) {
  const Catalogue& cat = catalogue();
  ASSERT_EQ(cat.objects.size(), 31u);
  for (const Object& o : cat.objects)
    EXPECT_TRUE(o.object_class == "threat" || o.object_class == "benign") << o.name << ": " << o.object_class;
  const auto set = [&](const std::string& token) { return names_of(cat, parse_object_set(cat, token, "t", true)); };
  EXPECT_EQ(set("family:handgun"), (std::set<std::string>{"gun", "handgun-subcompact", "handgun-compact",
                                                          "handgun-large", "plastic-handgun"}));
  EXPECT_EQ(set("family:knife"),
            (std::set<std::string>{"knife-paring", "knife-utility", "knife-chef", "ceramic-knife"}));
  EXPECT_EQ(set("family:pipe"), (std::set<std::string>{"iron-pipe", "pipe-short", "pipe-long"}));
  EXPECT_EQ(set("family:plate"), (std::set<std::string>{"metal-plate", "plate-small", "plate-large"}));
  EXPECT_EQ(set("class:threat").size(), 15u);
  EXPECT_EQ(set("class:threat").size() + set("class:benign").size(), cat.objects.size());
  // Names, classes and families compare as object names do: case and punctuation aside.
  EXPECT_EQ(set("Class:THREAT"), set("class:threat"));
  EXPECT_EQ(set("all").size(), cat.objects.size());
  EXPECT_EQ(set("Knife"), (std::set<std::string>{"knife-utility"}));  // an alias, not the family
}

// A run that names no pool draws the thesis's 12 and nothing else, all of them.
TEST(Objects, TheDefaultPoolIsTheThesisObjects) {
  const Catalogue& cat = catalogue();
  const std::set<std::string> thesis{"gun",         "iron-handle",   "iron-rod",    "compact-disk",
                                     "metal-strip", "metal-plate",   "pendant",     "iron-pipe",
                                     "belt-buckle", "ceramic-plate", "cement-tile", "mobile-phone"};
  EXPECT_EQ(names_of(cat, cat.default_pool), thesis);
  EXPECT_EQ(drawn({}), thesis);
}

// A pool of a class or family draws exactly its members, every one of them.
TEST(Objects, PoolsOfClassesAndFamiliesDrawTheirMembers) {
  const Catalogue& cat = catalogue();
  for (const char* token : {"class:benign", "class:threat", "family:knife", "family:handgun", "all"}) {
    const std::vector<int> pool = parse_object_set(cat, token, "--pool", true);
    EXPECT_EQ(drawn(pool), names_of(cat, pool)) << token;
  }
}

// The draws index the pool, so its order is the order it was listed in (a spec written
// before classes existed draws what it drew): each object where it first appears.
TEST(Objects, APoolKeepsTheOrderItIsListedIn) {
  const Catalogue& cat = catalogue();
  RunSpec spec;
  spec.pool = {"mobile-phone", "family:knife", "gun", "knife-chef"};
  std::vector<std::string> got;
  for (int o : generator_spec(spec, cat).pool) got.push_back(cat.objects[o].name);
  EXPECT_EQ(got, (std::vector<std::string>{"mobile-phone", "knife-paring", "knife-utility", "knife-chef",
                                           "ceramic-knife", "gun"}));
  spec.pool = {"gun", "pistol"};
  try {
    (void)generator_spec(spec, cat);
    ADD_FAILURE() << "gun and its alias were taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("listed twice"), std::string::npos) << e.what();
  }
}

TEST(Objects, RulesNameClassesAndFamilies) {
  const Catalogue& cat = catalogue();
  const ThreatRule threat(cat, "class:threat"), not_threat(cat, "!class:threat"),
      knife_and_benign(cat, "family:knife & class:benign");
  Scenario none, keys, bottle, both;
  keys.objects[0] = static_cast<int16_t>(test::variant_of(cat, "keys"));
  bottle.objects[5] = static_cast<int16_t>(test::variant_of(cat, "liquid-bottle"));
  both = keys;
  both.objects[9] = static_cast<int16_t>(test::variant_of(cat, "knife-chef"));
  EXPECT_FALSE(threat(none));
  EXPECT_FALSE(threat(keys));
  EXPECT_TRUE(threat(bottle));
  EXPECT_TRUE(threat(both));
  EXPECT_TRUE(not_threat(keys));
  EXPECT_FALSE(not_threat(both));
  EXPECT_TRUE(knife_and_benign(both));
  EXPECT_FALSE(knife_and_benign(bottle));
  // Drawn from everything, the rule is the class of what was drawn.
  GeneratorSpec spec;
  spec.pool = parse_object_set(cat, "all", "--pool", true);
  spec.rule = "class:threat";
  const Generator gen(cat, spec, 5);
  int threats = 0;
  for (int i = 0; i < 2000; ++i) {
    const Scenario s = gen(i);
    bool any = false;
    for (int16_t v : s.objects) any = any || (v != kNoObject && cat.object_of(v).object_class == "threat");
    ASSERT_EQ(s.label, any ? 1 : 0) << i;
    threats += s.label;
  }
  EXPECT_GT(threats, 500);
  EXPECT_LT(threats, 1900);
  for (const char* bad : {"class:weapon", "family:", "family:gun", "class"}) {
    try {
      ThreatRule r(cat, bad, "--rule");
      ADD_FAILURE() << bad << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--rule"), std::string::npos) << e.what();
    }
  }
  try {
    ThreatRule r(cat, "class:weapon", "--rule");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("threat and benign"), std::string::npos) << e.what();
  }
}

// The metal detector sees what each kind carries: nothing of the non-metal threats, a
// chef's knife more than a paring knife, in both models.
TEST(Objects, NonMetalThreatsLeaveTheDetectorAlone) {
  const Catalogue& cat = catalogue();
  auto ref = make_reference_backend(cat, test::assets());
  for (Model model : {Model::thesis, Model::physics}) {
    Plan plan = model == Model::physics ? test::physics_plan(3) : Plan{};
    plan.images = 0;
    plan.model.metal_noise = 0;
    std::vector<Scenario> scenes(1);  // scenario 0 carries nothing
    const std::vector<std::string> objects{"ceramic-knife", "liquid-bottle", "sheet-explosive", "wallet",
                                           "knife-paring",  "knife-chef",    "plastic-handgun", "handgun-large"};
    for (const std::string& name : objects) {
      Scenario s;
      s.objects[4] = static_cast<int16_t>(test::variant_of(cat, name));
      scenes.push_back(s);
    }
    BatchOutput out;
    ref->run(test::batch_of(scenes), plan, out);
    const auto drop = [&](size_t i) {
      int d = 0;
      for (int z = 0; z < out.layout.zones; ++z) d += out.metal_of(0)[z] - out.metal_of(i)[z];
      return d;
    };
    std::map<std::string, int> d;
    for (size_t k = 0; k < objects.size(); ++k) d[objects[k]] = drop(k + 1);
    for (const char* silent : {"ceramic-knife", "liquid-bottle", "sheet-explosive", "wallet"})
      EXPECT_EQ(d[silent], 0) << silent << ", model " << static_cast<int>(model);
    EXPECT_GT(d["knife-paring"], 0) << static_cast<int>(model);
    EXPECT_GT(d["knife-chef"], d["knife-paring"]) << static_cast<int>(model);
    EXPECT_GT(d["handgun-large"], d["plastic-handgun"]) << static_cast<int>(model);
  }
}

// Crowds of every object (random_scenario draws the default pool's): the kernels' images,
// features and metal are the reference's within each model's tolerance table, in the
// standard and exact tiers; and the tabulated features path's (physics, fast tier) where
// the pairs of the new drawings meet.
TEST(Objects, CrowdsOfEveryObjectAreTheReferences) {
  const Catalogue& cat = catalogue();
  GeneratorSpec spec;
  spec.pool = parse_object_set(cat, "all", "--pool", true);
  spec.min_objects = 3;
  spec.max_objects = 8;
  const Generator gen(cat, spec, 13);
  std::vector<Scenario> scenes;
  for (int i = 0; i < (test::kSanitized ? 10 : 40); ++i) scenes.push_back(gen(i));
  const SceneBatch batch = test::batch_of(scenes, 300);
  auto ref = make_reference_backend(cat, test::assets());
  auto ocl = make_opencl_backend(cat, test::assets(), test::runtime());
  for (Model model : {Model::thesis, Model::physics})
    for (Tier tier : {Tier::standard, Tier::exact}) {
      SCOPED_TRACE(std::string(model == Model::physics ? "physics " : "thesis ") + tier_name(tier));
      Plan plan = model == Model::physics ? test::physics_plan(6) : Plan{};
      plan.fidelity = tier_fidelity(tier);
      BatchOutput r, k;
      ref->run(batch, plan, r);
      ocl->run(batch, plan, k);
      EXPECT_EQ(check_tolerance(compare_outputs(k, r), model_tolerance(model, tier)), "");
    }
  // Features only in the fast tier, noise-free and in a window no scene leaves (as
  // Clothing.OutfitsAreTheReferencesOnEveryPath): the tables' sums against the reference's.
  Plan fast = test::physics_plan(6);
  fast.fidelity = tier_fidelity(Tier::fast);
  fast.model.netd = 0;
  fast.model.ir_netd = 0;
  Plan features;
  BatchOutput k;
  test::expect_raw_features_parity(*ref, *ocl, batch, fast, "tabulated", features, k);
}

// The features paths tabulate the drawings their batches carry, and tabulate again with
// the union when a batch brings more: a backend that met the thesis's objects first gives,
// for a batch of the new ones, the very features of a backend that met only that batch,
// and (thesis model) those of the rendered views pooled.
TEST(Objects, FeatureTablesGrowWithTheDrawingsTheBatchesCarry) {
  const Catalogue& cat = catalogue();
  GeneratorSpec thesis_spec, all_spec;
  all_spec.pool = parse_object_set(cat, "all", "--pool", true);
  const Generator thesis_objects(cat, thesis_spec, 8), all_objects(cat, all_spec, 9);
  std::vector<Scenario> first, second;
  for (int i = 0; i < 60; ++i) first.push_back(thesis_objects(i));
  for (int i = 0; i < 60; ++i) second.push_back(all_objects(i));
  const SceneBatch a = test::batch_of(first, 0), b = test::batch_of(second, 60);
  Plan thesis;
  thesis.images = 0;
  Plan physics = test::physics_plan(4);
  physics.images = 0;
  physics.fidelity = tier_fidelity(Tier::fast);
  for (const auto& [plan, path] : {std::pair{thesis, "thesis_sparse_features"}, {physics, "physics_raw_features"}}) {
    auto grown = make_opencl_backend(cat, test::assets(), test::runtime());
    auto fresh = make_opencl_backend(cat, test::assets(), test::runtime());
    ASSERT_EQ(test::features_path(*grown, plan), path);
    BatchOutput ignored, from_grown, from_fresh;
    grown->run(a, plan, ignored);
    grown->run(b, plan, from_grown);
    fresh->run(b, plan, from_fresh);
    EXPECT_EQ(from_grown.features, from_fresh.features) << path;
    if (plan.model.model == Model::thesis) {
      Plan dense = plan;
      dense.fidelity.pooling = Pooling::dense;
      BatchOutput pooled;
      fresh->run(b, dense, pooled);
      EXPECT_EQ(from_grown.features, pooled.features);
    }
  }
}

Catalogue parse(const std::string& text) { return parse_catalogue(text, "my.toml", "."); }

std::string refusal(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(taken)";
}

TEST(Objects, BadClassesFamiliesAndPoolsAreRefusedNamingTheLine) {
  const std::string text = test::slurp(fs::path(PORTALSIM_SOURCE_DIR) / "scenarios" / "catalogue.toml");
  const auto with_gun_line = [&](const std::string& line) {
    std::string t = text;
    t.insert(t.find('\n', t.find("name = \"gun\"")) + 1, line + "\n");
    return t;
  };
  std::string e = refusal(with_gun_line("klass = \"threat\""));
  EXPECT_NE(e.find("klass"), std::string::npos) << e;
  e = refusal(std::regex_replace(text, std::regex("class = \"threat\"\nfamily = \"handgun\""),
                                 "class = \"a threat!\"\nfamily = \"handgun\"",
                                 std::regex_constants::format_first_only));
  EXPECT_NE(e.find("my.toml:"), std::string::npos) << e;
  EXPECT_NE(e.find("objects[1].class"), std::string::npos) << e;
  e = refusal(std::regex_replace(text, std::regex("default_pool = \\[\"gun\""), "default_pool = [\"gnu\""));
  EXPECT_NE(e.find("default_pool[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("gnu"), std::string::npos) << e;
  e = refusal(std::regex_replace(text, std::regex("default_pool = \\[\"gun\""), "default_pool = [\"pistol\", \"gun\""));
  EXPECT_NE(e.find("default_pool[2]"), std::string::npos) << e;
  EXPECT_NE(e.find("listed twice"), std::string::npos) << e;
  e = refusal(std::regex_replace(text, std::regex("name = \"wallet\""), "name = \"All\""));
  EXPECT_NE(e.find(".name"), std::string::npos) << e;
  // Without default_pool, a catalogue's runs draw every object (a user's catalogue as before).
  const Catalogue all = parse(std::regex_replace(text, std::regex("default_pool = \\[[^\\]]*\\]"), ""));
  EXPECT_EQ(all.default_pool.size(), all.objects.size());
}

// On the command line: a pool of a class, the rule of a class, the rows' labels and objects
// as scenarios.csv records them; a misspelt class named with its flag, nothing written.
TEST(Objects, GenerateTakesClassesInPoolsAndRules) {
  test::TempDir t;
  const fs::path out = t.w() / "benign";
  const auto r = test::generate(t,
                                {"--count", "300", "--seed", "4", "--what", "features", "--format", "npy", "--pool",
                                 "class:benign,family:knife", "--rule", "class:threat"},
                                out);
  ASSERT_EQ(r.status, 0) << test::describe(r);
  std::ifstream csv(out / "scenarios.csv");
  std::string line;
  std::getline(csv, line);
  int rows = 0, threats = 0;
  std::set<std::string> seen;
  while (std::getline(csv, line)) {
    std::stringstream ss(line);
    std::vector<std::string> f;
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    ASSERT_GE(f.size(), 16u) << line;
    bool knife = false;
    for (size_t c = 2; c < 15; ++c) {
      if (f[c] == "none") continue;
      const std::string name = f[c].substr(0, f[c].find(':'));
      seen.insert(name);
      knife = knife || catalogue().objects[catalogue().find_object(name)].family == "knife";
    }
    EXPECT_EQ(f.back(), knife ? "yes" : "no") << line;
    threats += knife;
    ++rows;
  }
  EXPECT_EQ(rows, 300);
  EXPECT_GT(threats, 0);
  for (const std::string& name : seen) {
    const Object& o = catalogue().objects[catalogue().find_object(name)];
    EXPECT_TRUE(o.object_class == "benign" || o.family == "knife") << name;
  }
  const fs::path bad = t.w() / "bad";
  const auto b = test::generate(t, {"--count", "10", "--pool", "class:weapons"}, bad);
  EXPECT_NE(b.status, 0);
  EXPECT_NE(b.err.find("--pool"), std::string::npos) << b.err;
  EXPECT_NE(b.err.find("threat and benign"), std::string::npos) << b.err;
  EXPECT_FALSE(fs::exists(bad));
}

}  // namespace
}  // namespace portalsim
