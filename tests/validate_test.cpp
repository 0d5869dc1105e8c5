// `portalsim validate` as a user meets it: WEKA scores on small generated tables, and
// bad input refused with a message naming the file.
#include <nlohmann/json.hpp>
#include <random>

#include "run_binary.h"

namespace {

namespace fs = std::filesystem;
using portalsim::test::finish;
using portalsim::test::slurp;
using portalsim::test::spit;
using portalsim::test::start;

fs::path fresh_dir() {
  char tmpl[] = "/tmp/portalsim-validate-XXXXXX";
  if (!::mkdtemp(tmpl)) throw std::runtime_error("mkdtemp failed");
  return tmpl;
}

// Two attributes; `a` separates the classes unless `shuffled`, then labels are random.
std::string table(int n, unsigned seed, bool shuffled) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 0.5);
  std::bernoulli_distribution coin(0.5);
  std::ostringstream s;
  s << "@relation t\n@attribute a numeric\n@attribute b numeric\n@attribute class {gun,none}\n@data\n";
  for (int i = 0; i < n; ++i) {
    const bool gun = i % 2;
    const bool label = shuffled ? coin(rng) : gun;
    s << (gun ? 1.5 : 0.0) + noise(rng) << "," << noise(rng) << "," << (label ? "gun" : "none") << "\n";
  }
  return s.str();
}

portalsim::test::Result validate(const fs::path& dir, const std::string& sim, const std::string& real) {
  return finish(start(dir / "cap", {"validate", "--sim", (dir / sim).string(), "--real", (dir / real).string(), "--out",
                                    (dir / "out").string(), "--folds", "5"}));
}

TEST(Validate, ScoresAllThreeClassifiersAndShuffledLabelsFallToChance) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  spit(d / "sim.arff", table(200, 1, false));
  spit(d / "real.arff", table(200, 2, false));
  spit(d / "shuffled.arff", table(200, 3, true));
  auto r = validate(d, "sim.arff", "real.arff");
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const auto same = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  for (const char* c : {"J48", "MultilayerPerceptron", "SMO"}) {
    EXPECT_GT(same["classifiers"][c]["sim_to_real"]["percent_correct"].get<double>(), 85) << c;
    EXPECT_GT(same["classifiers"][c]["real"]["percent_correct"].get<double>(), 85) << c;
  }
  EXPECT_NE(slurp(d / "out" / "report.md").find("| SMO |"), std::string::npos);
  fs::remove_all(d / "out");
  r = validate(d, "sim.arff", "shuffled.arff");
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const auto shuffled = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  for (const char* c : {"J48", "MultilayerPerceptron", "SMO"}) {
    const double acc = shuffled["classifiers"][c]["sim_to_real"]["percent_correct"].get<double>();
    EXPECT_GT(acc, 35) << c;
    EXPECT_LT(acc, 65) << c;
    const long wrong = shuffled["classifiers"][c]["sim_to_real"]["misclassified"].get<long>();
    EXPECT_NEAR(wrong, 200 * (100 - acc) / 100, 0.5) << c;
  }
  fs::remove_all(d);
}

TEST(Validate, BadInputGetsAMessageAndNoReport) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  spit(d / "ok.arff", table(20, 1, false));
  spit(d / "other.arff",
       "@relation t\n@attribute a numeric\n@attribute c numeric\n@attribute class {gun,none}\n@data\n1,2,gun\n");
  spit(d / "single.arff",
       "@relation t\n@attribute a numeric\n@attribute b numeric\n@attribute class {gun,none}\n"
       "@data\n1,2,gun\n2,3,gun\n3,4,gun\n4,5,gun\n5,6,gun\n");
  spit(d / "few.arff",
       "@relation t\n@attribute a numeric\n@attribute b numeric\n@attribute class {gun,none}\n"
       "@data\n1,2,gun\n2,3,none\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"other.arff", "other.arff:3: attribute '@attribute c numeric' differs"},
      {"single.arff", "single value"},
      {"few.arff", "fewer than the 5 cross-validation folds"},
  };
  for (const auto& [file, message] : cases) {
    const auto r = validate(d, "ok.arff", file);
    EXPECT_TRUE(r.exited && r.status == 3) << portalsim::test::describe(r);  // 3: a bad input file
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(d / "out")) << file;
  }
  // No java on PATH: the run stops with a message instead of a report.
  const auto r = finish(portalsim::test::start_program(
      d / "cap", "/usr/bin/env",
      {"PATH=/nonexistent", PORTALSIM_BINARY, "validate", "--sim", (d / "ok.arff").string(), "--real",
       (d / "ok.arff").string(), "--out", (d / "out").string(), "--folds", "5"}));
  EXPECT_TRUE(r.exited && r.status != 0) << portalsim::test::describe(r);
  EXPECT_NE(r.err.find("java not found"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

}  // namespace
