// `portalsim validate` as a user meets it: WEKA scores and t-tests on small generated
// tables, WEKA's own command line as the reference for the folds, the t-tests against
// scipy, and bad input refused with a message naming the file.
#include <fcntl.h>
#include <unistd.h>

#include <boost/math/distributions/students_t.hpp>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <tuple>

#include "base/error.h"
#include "cli/validate_stats.h"
#include "cli/validate_tables.h"
#include "cli/weka.h"
#include "io/table_fields.h"
#include "run_binary.h"
#include "sink/feature_rows.h"
#include "sink/h5_file.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir() { return portalsim::test::make_temp_dir("portalsim-validate"); }

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

portalsim::test::Result validate(const fs::path& dir, const std::string& sim, const std::string& real,
                                 std::vector<std::string> more = {}) {
  std::vector<std::string> args = {
      "validate", "--sim", (dir / sim).string(), "--real", (dir / real).string(), "--out", (dir / "out").string(),
      "--folds",  "5"};
  args.insert(args.end(), more.begin(), more.end());
  return finish(start(dir / "cap", args), 400);
}

// A run refused with exit `status` (3: a bad input file), its message holding `says`, that
// leaves no `out`.
void expect_refused(const portalsim::test::Result& r, int status, const std::string& says, const fs::path& out) {
  EXPECT_TRUE(r.exited && r.status == status) << portalsim::test::describe(r);
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << says;
}

// scipy 1.10 (Debian python3-scipy):
//   a=[80,90,85,70,75,95,88,82,79,91]; b=[78,85,80,72,70,90,84,75,80,86]
//   stats.ttest_ind(a, b)  -> statistic=1.0991902374394489, pvalue=0.28617004408826807
//   d=np.array(a)-np.array(b); t=d.mean()/np.sqrt((1/10+1/9)*d.var(ddof=1))
//   t -> 2.612781159415557; 2*stats.t.sf(abs(t), 9) -> 0.028142110978438096
TEST(Validate, TTestsAgreeWithScipy) {
  const std::vector<double> a = {80, 90, 85, 70, 75, 95, 88, 82, 79, 91}, b = {78, 85, 80, 72, 70, 90, 84, 75, 80, 86};
  const auto two = portalsim::cli::student_two_sample(a, b);
  EXPECT_NEAR(two.t, 1.0991902374394489, 1e-12);
  EXPECT_EQ(two.df, 18);
  EXPECT_NEAR(two.p, 0.28617004408826807, 1e-10);
  std::vector<double> d;
  for (size_t i = 0; i < a.size(); ++i) d.push_back(a[i] - b[i]);
  const auto corrected = portalsim::cli::corrected_resampled(d, 1.0 / 9);
  EXPECT_NEAR(corrected.t, 2.612781159415557, 1e-12);
  EXPECT_EQ(corrected.df, 9);
  EXPECT_NEAR(corrected.p, 0.028142110978438096, 1e-10);
  // No spread: equal means give P = 1, different ones P = 0.
  EXPECT_EQ(portalsim::cli::student_two_sample({90, 90}, {90, 90}).p, 1);
  EXPECT_EQ(portalsim::cli::corrected_resampled({5, 5, 5}, 0.1).p, 0);
}

TEST(Validate, SameSpecIsNotToldApartAndShuffledLabelsAre) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  spit(d / "sim.arff", table(200, 1, false));
  spit(d / "real.arff", table(200, 2, false));
  spit(d / "shuffled.arff", table(200, 3, true));
  const std::vector<std::string> opts = {"--classifiers", "j48,svm", "--runs", "2", "--curve-steps", "2"};
  auto r = validate(d, "sim.arff", "real.arff", opts);
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const auto same = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  EXPECT_EQ(same["analyses"].size(), 1u);  // no region or block columns: one analysis of all
  for (const char* c : {"J48", "SMO"}) {
    const auto& s = same["analyses"]["all"]["classifiers"][c];
    EXPECT_GT(s["corrected_resampled_t_test"]["p"].get<double>(), 0.05) << c;
    EXPECT_GT(s["sim_to_real"]["percent_correct"].get<double>(), 85) << c;
    EXPECT_GT(s["real"]["mean_percent_correct"].get<double>(), 85) << c;
    EXPECT_EQ(s["real"]["runs"].size(), 2u) << c;
    EXPECT_EQ(s["real"]["runs"][0]["folds"].size(), 5u) << c;
    EXPECT_EQ(s["learning_curve"].size(), 3u) << c;
    EXPECT_EQ(s["learning_curve"][2]["sim_added"].get<int>(), 200) << c;
  }
  EXPECT_NE(same["analyses"]["all"]["classifiers"]["J48"]["trees"]["real"].get<std::string>().find("J48 pruned tree"),
            std::string::npos);
  const std::string md = slurp(d / "out" / "report.md");
  EXPECT_NE(md.find("| SMO |"), std::string::npos);
  EXPECT_NE(md.find("(corrected resampled t-test, t = "), std::string::npos);
  EXPECT_NE(md.find("(two-sample t-test)"), std::string::npos);
  EXPECT_NE(md.find("J48 pruned tree"), std::string::npos);
  EXPECT_GT(fs::file_size(d / "out" / "accuracy.png"), 1000u);
  EXPECT_GT(fs::file_size(d / "out" / "curve.png"), 1000u);
  fs::remove_all(d / "out");

  r = validate(d, "sim.arff", "shuffled.arff", opts);
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const auto shuffled = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  for (const char* c : {"J48", "SMO"}) {
    const auto& s = shuffled["analyses"]["all"]["classifiers"][c];
    EXPECT_LT(s["corrected_resampled_t_test"]["p"].get<double>(), 0.05) << c;
    EXPECT_LT(s["two_sample_t_test"]["mean_p"].get<double>(), 0.05) << c;
    const double acc = s["sim_to_real"]["percent_correct"].get<double>();
    EXPECT_GT(acc, 35) << c;
    EXPECT_LT(acc, 65) << c;
    const long wrong = s["sim_to_real"]["misclassified"].get<long>();
    EXPECT_NEAR(wrong, 200 * (100 - acc) / 100, 0.5) << c;
  }
  fs::remove_all(d);
}

// WEKA's command line's count of correctly classified instances in its section `section`.
long wekas_own_correct(const fs::path& cap, std::vector<std::string> args, const std::string& section) {
  args.insert(args.begin(), {"java", "-cp", "/usr/share/java/weka.jar"});
  const auto w = finish(portalsim::test::start_program(cap, "/usr/bin/env", args));
  EXPECT_TRUE(w.exited && w.status == 0) << portalsim::test::describe(w);
  const size_t at = w.out.find("Correctly Classified Instances", w.out.find(section));
  EXPECT_NE(at, std::string::npos) << w.out;
  if (at == std::string::npos) return -1;
  std::istringstream in(w.out.substr(at + 30));
  long correct = -1;
  in >> correct;
  return correct;
}

// The overall accuracy of the folds equals that of WEKA's own command line for the seed.
TEST(Validate, FoldsAreWekasOwn) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  spit(d / "sim.arff", table(120, 4, false));
  spit(d / "real.arff", table(120, 5, true));
  auto r = validate(d, "sim.arff", "real.arff",
                    {"--classifiers", "j48,svm", "--runs", "1", "--seed", "7", "--curve-steps", "0"});
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const auto report = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  for (const auto& [label, cls] : std::vector<std::pair<std::string, std::string>>{
           {"J48", "weka.classifiers.trees.J48"}, {"SMO", "weka.classifiers.functions.SMO"}}) {
    for (const char* set : {"real", "sim"}) {
      const long correct = wekas_own_correct(
          d / "cap", {cls, "-o", "-t", (d / (std::string(set) + ".arff")).string(), "-x", "5", "-s", "7"},
          "=== Stratified cross-validation ===");
      const auto& run = report["analyses"]["all"]["classifiers"][label][set]["runs"][0];
      EXPECT_EQ(run["correct"].get<long>(), correct) << label << " " << set;
      double sum = 0;
      for (double f : run["folds"]) sum += f * 24 / 100;  // 120 instances, 5 stratified folds of 24
      EXPECT_NEAR(sum, static_cast<double>(correct), 1e-6) << label << " " << set;
    }
  }
  fs::remove_all(d);
}

// transfer's and tradeoff's one JVM (cli::weka_scores): a classifier trained once scores each
// test set as WEKA's command line `-t -T` does, and a cross-validation as `-x -s` does.
TEST(Weka, OneJvmScoresAsWekasCommandLine) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  spit(d / "train.arff", table(120, 4, false));
  spit(d / "near.arff", table(90, 5, false));
  spit(d / "shuffled.arff", table(60, 6, true));
  const std::string train = (d / "train.arff").string(), near = (d / "near.arff").string(),
                    shuffled = (d / "shuffled.arff").string();
  std::string why;
  const auto got = portalsim::cli::weka_scores(
      {{.classifier = "j48", .train = train, .tests = {near, shuffled}, .folds = 0, .seed = 0},
       {.classifier = "svm", .train = shuffled, .tests = {}, .folds = 5, .seed = 7},
       {.classifier = "j48", .train = near, .tests = {}, .folds = 10, .seed = 1}},
      why);
  ASSERT_TRUE(got) << why;
  ASSERT_EQ(got->size(), 3u);
  ASSERT_EQ((*got)[0].size(), 2u);
  const std::string j48 = "weka.classifiers.trees.J48", smo = "weka.classifiers.functions.SMO";
  const std::string on_test = "=== Error on test data ===", cv = "=== Stratified cross-validation ===";
  EXPECT_EQ((*got)[0][0].correct, wekas_own_correct(d / "cap", {j48, "-o", "-t", train, "-T", near}, on_test));
  EXPECT_EQ((*got)[0][0].correct + (*got)[0][0].misclassified, 90);
  EXPECT_EQ((*got)[0][1].correct, wekas_own_correct(d / "cap", {j48, "-o", "-t", train, "-T", shuffled}, on_test));
  EXPECT_EQ((*got)[1][0].correct, wekas_own_correct(d / "cap", {smo, "-o", "-t", shuffled, "-x", "5", "-s", "7"}, cv));
  EXPECT_EQ((*got)[2][0].correct, wekas_own_correct(d / "cap", {j48, "-o", "-t", near}, cv));
  EXPECT_EQ((*got)[2][0].correct + (*got)[2][0].misclassified, 90);
  // A test set whose header is not the training set's is WEKA's failure, named.
  spit(d / "other.arff", "@relation o\n@attribute a numeric\n@attribute class {gun,none}\n@data\n1,gun\n");
  EXPECT_FALSE(portalsim::cli::weka_scores(
      {{.classifier = "j48", .train = train, .tests = {(d / "other.arff").string()}, .folds = 0, .seed = 0}}, why));
  EXPECT_NE(why.find("different headers"), std::string::npos) << why;
  fs::remove_all(d);
}

TEST(Validate, ReadsCsvAndSelectsFeatureSets) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  auto csv = [](unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0, 0.3);
    std::string s = "mmw_r0_c0,mmw_r0_c1,region1,zone1,class\n";
    for (int i = 0; i < 60; ++i) {
      const bool pos = i % 2;
      s += std::to_string(noise(rng)) + "," + std::to_string(noise(rng)) + "," +
           std::to_string((pos ? 2 : 0) + noise(rng)) + "," + std::to_string(noise(rng)) + "," +
           (pos ? "positive" : "negative") + "\n";
    }
    return s;
  };
  spit(d / "sim.csv", csv(1));
  spit(d / "real.csv", csv(2));
  const std::vector<std::string> opts = {"--classifiers", "j48", "--runs", "1", "--curve-steps", "0", "--features"};
  auto with = [&](const char* features) {
    auto v = opts;
    v.push_back(features);
    return v;
  };
  auto r = validate(d, "sim.csv", "real.csv", with("blocks"));
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  auto report = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  ASSERT_EQ(report["analyses"].size(), 1u);
  const auto blocks = report["analyses"]["blocks"];
  EXPECT_EQ(blocks["attributes"].get<int>(), 3);  // two blocks and a zone; the region mean dropped
  EXPECT_EQ(blocks["thesis_tables"], nlohmann::json({"6.2", "6.4", "6.6"}));
  EXPECT_NE(slurp(d / "out" / "report.md").find("Not computed (`--curve-steps 0`)"), std::string::npos);
  EXPECT_FALSE(blocks["classifiers"]["J48"].contains("learning_curve"));
  EXPECT_LT(blocks["classifiers"]["J48"]["real"]["mean_percent_correct"].get<double>(), 75);
  fs::remove_all(d / "out");
  r = validate(d, "sim.csv", "real.csv", with("regions"));
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  report = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  const auto regions = report["analyses"]["regions"];
  EXPECT_EQ(regions["attributes"].get<int>(), 2);  // the region mean and a zone
  EXPECT_GT(regions["classifiers"]["J48"]["real"]["mean_percent_correct"].get<double>(), 90);
  fs::remove_all(d / "out");

  // both: the two analyses side by side, as the thesis's tables 6.1-6.6; each equals its own run.
  r = validate(d, "sim.csv", "real.csv", with("both"));
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  report = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  ASSERT_EQ(report["analyses"].size(), 2u);
  EXPECT_EQ(report["analyses"]["regions"], regions);
  EXPECT_EQ(report["analyses"]["blocks"], blocks);
  const std::string md = slurp(d / "out" / "report.md");
  size_t at = 0;
  for (const char* table :
       {"### Real data, region means (as thesis table 6.1)", "### Real data, block means (as thesis table 6.2)",
        "### Simulated data, region means (as thesis table 6.3)",
        "### Simulated data, block means (as thesis table 6.4)",
        "### Combined data, region means (as thesis table 6.5)",
        "### Combined data, block means (as thesis table 6.6)"}) {
    const size_t next = md.find(table, at);
    EXPECT_NE(next, std::string::npos) << table << " (in this order)\n" << md;
    if (next != std::string::npos) at = next;
  }
  EXPECT_NE(md.find("| J48 | region means | P = "), std::string::npos);
  EXPECT_NE(md.find("| J48 | block means | P = "), std::string::npos);
  EXPECT_NE(md.find("## J48 trees, region means"), std::string::npos);
  EXPECT_NE(md.find("## J48 trees, block means"), std::string::npos);
  fs::remove_all(d / "out");

  // A table without block means cannot give a blocks analysis.
  spit(d / "plain.csv", "a,b,class\n1,2,gun\n2,3,none\n");
  r = finish(start(d / "cap", {"validate", "--sim", (d / "plain.csv").string(), "--real", (d / "plain.csv").string(),
                               "--out", (d / "out").string(), "--features", "blocks"}));
  expect_refused(r, 3, "plain.csv: --features blocks: no block-mean attributes", d / "out");
  fs::remove_all(d);
}

// Folders of scenario folders become tables as `portalsim features` makes them; --grid 5x5
// (block 40 on the 200x200 MMW views) gives the thesis's 69 attributes (appendix D.4).
TEST(Validate, ReadsScenarioFolders) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  for (const char* seed : {"3", "4"}) {
    const auto g = finish(
        start(d / "cap", {"generate", "--spec", PORTALSIM_SOURCE_DIR "/scenarios/case2-rod-plate.toml", "--count", "30",
                          "--seed", seed, "--what", "images", "--out", (d / (std::string("set") + seed)).string()}));
    ASSERT_TRUE(g.exited && g.status == 0) << portalsim::test::describe(g);
  }
  const auto f = finish(start(
      d / "cap", {"features", (d / "set3" / "images").string(), "--block", "40", "--out", (d / "set3.arff").string()}));
  ASSERT_TRUE(f.exited && f.status == 0) << portalsim::test::describe(f);
  const auto r =
      validate(d, "set3/images", "set4/images",
               {"--grid", "5x5", "--features", "blocks", "--classifiers", "j48", "--runs", "1", "--curve-steps", "0"});
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const auto report = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  EXPECT_EQ(report["analyses"]["blocks"]["attributes"].get<int>(), 69);  // 2 views x 25 block means + 19 zones
  EXPECT_EQ(report["sim_instances"].get<int>(), 30);
  EXPECT_EQ(report["real_instances"].get<int>(), 30);
  // The same rows as `portalsim features` writes: J48 on the whole set gives the same tree.
  fs::remove_all(d / "out");
  const auto t =
      validate(d, "set3.arff", "set4/images",
               {"--block", "40", "--features", "blocks", "--classifiers", "j48", "--runs", "1", "--curve-steps", "0"});
  ASSERT_TRUE(t.exited && t.status == 0) << portalsim::test::describe(t);
  const auto from_table = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  const auto& a = from_table["analyses"]["blocks"]["classifiers"]["J48"];
  const auto& b = report["analyses"]["blocks"]["classifiers"]["J48"];
  EXPECT_EQ(a["trees"]["sim"], b["trees"]["sim"]);
  EXPECT_EQ(a["sim"]["runs"], b["sim"]["runs"]);
  fs::remove_all(d / "out");
  const auto g = validate(d, "set3/images", "set4/images", {"--grid", "7x3"});
  EXPECT_TRUE(g.exited && g.status != 0) << portalsim::test::describe(g);
  EXPECT_NE(g.err.find("--grid: no square block cuts every pooled view into 7x3 blocks"), std::string::npos) << g.err;
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

// A real set labelled by another rule (iron rod AND metal plate, against gun) is told by a
// far lower sim-to-real accuracy than one labelled by the same rule.
TEST(Validate, AnotherRuleLowersSimToReal) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  const std::vector<std::tuple<std::string, std::string, std::string>> sets = {
      {"sim", "1", "gun"}, {"same", "2", "gun"}, {"other", "3", "iron-rod & metal-plate"}};
  for (const auto& [name, seed, rule] : sets) {
    const auto g = finish(start(d / "cap", {"generate", "--count", "300", "--seed", seed, "--rule", rule, "--balance",
                                            "--block", "40", "--out", (d / name).string()}));
    ASSERT_TRUE(g.exited && g.status == 0) << portalsim::test::describe(g);
  }
  double accuracy[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    fs::remove_all(d / "out");
    const auto r = validate(d, "sim/features.arff", k == 0 ? "same/features.arff" : "other/features.arff",
                            {"--classifiers", "j48", "--runs", "1", "--curve-steps", "0", "--features", "blocks"});
    ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
    const auto report = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    accuracy[k] = report["analyses"]["blocks"]["classifiers"]["J48"]["sim_to_real"]["percent_correct"].get<double>();
  }
  EXPECT_GT(accuracy[0], 75);
  EXPECT_LT(accuracy[1], accuracy[0] - 10) << "same rule " << accuracy[0] << "%, other rule " << accuracy[1] << "%";
  fs::remove_all(d);
}

// A data.h5 of `generate --format h5` is read as the same run's ARFF: the same report.
TEST(Validate, ReadsH5AsTheSameRunsArff) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  for (const char* seed : {"5", "6"}) {
    const auto g =
        finish(start(d / "cap", {"generate", "--spec", PORTALSIM_SOURCE_DIR "/scenarios/case2-rod-plate.toml",
                                 "--count", "120", "--seed", seed, "--block", "40", "--format", "arff,h5", "--out",
                                 (d / (std::string("g") + seed)).string()}));
    ASSERT_TRUE(g.exited && g.status == 0) << portalsim::test::describe(g);
  }
  const std::vector<std::string> opts = {"--classifiers", "j48", "--runs", "2", "--curve-steps", "1"};
  nlohmann::json reports[2];
  for (int k = 0; k < 2; ++k) {
    fs::remove_all(d / "out");
    const std::string file = k == 0 ? "features.arff" : "data.h5";
    const auto r = validate(d, "g5/" + file, "g6/" + file, opts);
    ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
    reports[k] = nlohmann::json::parse(slurp(d / "out" / "report.json"));
  }
  EXPECT_EQ(reports[1]["sim_instances"].get<int>(), 120);
  EXPECT_EQ(reports[1]["analyses"].size(), 2u);
  EXPECT_EQ(reports[1]["analyses"]["blocks"]["attributes"].get<int>(), 69);
  EXPECT_EQ(reports[1]["analyses"]["regions"]["attributes"].get<int>(), 32);
  EXPECT_EQ(reports[0]["analyses"], reports[1]["analyses"]);  // every fold, tree and P value

  // An h5 that is not HDF5, and one without features (--what images), are refused.
  spit(d / "bad.h5", "not an HDF5 file\n");
  const auto g = finish(start(
      d / "cap", {"generate", "--count", "10", "--what", "images", "--format", "h5", "--out", (d / "imgs").string()}));
  ASSERT_TRUE(g.exited && g.status == 0) << portalsim::test::describe(g);
  for (const auto& [file, message] : std::vector<std::pair<std::string, std::string>>{
           {"bad.h5", "bad.h5: not an HDF5 file"}, {"imgs/data.h5", "imgs/data.h5: has no \"features\" dataset"}}) {
    fs::remove_all(d / "out");
    const auto r = validate(d, "g5/data.h5", file);
    expect_refused(r, 3, message, d / "out");
  }
  fs::remove_all(d);
}

// A data.h5 may hold any float (the fuzzer found one past llround's long long): finite ones
// are written so they read back as the same float, a NaN or infinity is refused naming the
// row and column.
TEST(ValidateTables, H5FeaturesPastFixedPointReadBackAndNonFiniteAreRefused) {
  const auto text = [](float v) {
    std::string s;
    portalsim::append_number(s, v);
    return s;
  };
  EXPECT_EQ(text(1.5f), "1.5");
  EXPECT_EQ(text(-0.25f), "-0.25");
  EXPECT_EQ(text(0.0f), "0");
  for (const float big : {1e30f, -1e30f, 9.5e14f, -9.5e14f, std::numeric_limits<float>::max()}) {
    const std::string s = text(big);
    float back = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), back);
    EXPECT_TRUE(ec == std::errc() && end == s.data() + s.size() && back == big) << big << " written as " << s;
  }

  const fs::path d = fresh_dir();
  portalsim::H5Layout layout;
  layout.rows = 2;
  layout.datasets = {{"features", portalsim::TensorType::f32, {2}, {"a", "b"}},
                     {"metal", portalsim::TensorType::u8, {1}, {}},
                     {"label", portalsim::TensorType::u8, {}, {}}};
  const auto write = [&](const std::string& name, const std::array<float, 4>& features) {
    const std::string path = (d / name).string();
    const portalsim::H5InPlace place = portalsim::create_h5_in_place(path, layout);
    const int fd = ::open(path.c_str(), O_WRONLY);
    ASSERT_GE(fd, 0);
    const uint8_t metal[2] = {3, 4}, label[2] = {0, 1};
    for (uint64_t r = 0; r < 2; ++r) {
      portalsim::write_at(fd, reinterpret_cast<const char*>(&features[2 * r]), 8, place.at(0, r, 8), path);
      portalsim::write_at(fd, reinterpret_cast<const char*>(&metal[r]), 1, place.at(1, r, 1), path);
      portalsim::write_at(fd, reinterpret_cast<const char*>(&label[r]), 1, place.at(2, r, 1), path);
    }
    ::close(fd);
  };
  write("big.h5", {1.5f, 1e30f, -3e20f, 2.0f});
  const portalsim::cli::Table t = portalsim::cli::read_h5_table((d / "big.h5").string());
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0], (std::vector<std::string>{"1.5", text(1e30f), "3", "negative"}));
  EXPECT_EQ(t.rows[1], (std::vector<std::string>{text(-3e20f), "2", "4", "positive"}));
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    write("bad.h5", {1.5f, 2.0f, 3.0f, bad});
    try {
      (void)portalsim::cli::read_h5_table((d / "bad.h5").string());
      ADD_FAILURE() << bad << " was read";
    } catch (const portalsim::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.h5: dataset features, row 1, column b: "), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(" is not a number generate writes"), std::string::npos) << e.what();
    }
  }
  fs::remove_all(d);
}

double mean_of(const std::string& arff, const std::string& column) {
  std::istringstream in(arff);
  std::string line;
  int index = -1, n = 0, count = 0;
  double sum = 0;
  bool data = false;
  while (std::getline(in, line)) {
    if (line.rfind("@attribute ", 0) == 0) {
      if (line.substr(11, column.size() + 1) == column + " ") index = n;
      ++n;
    } else if (line.rfind("@data", 0) == 0) {
      data = true;
    } else if (data && !line.empty() && index >= 0) {
      std::istringstream row(line);
      std::string v;
      for (int i = 0; i <= index; ++i) std::getline(row, v, ',');
      sum += std::stod(v);
      ++count;
    }
  }
  return count ? sum / count : -1;
}

// --demo: the simulated set is `generate`'s own, the "real" one comes through a catalogue of
// altered image files, and the report has both feature sets' tables with sane numbers.
TEST(Validate, DemoMakesBothSetsAndTheReport) {
  const fs::path d = fresh_dir();
  fs::create_directories(d / "cap");
  const auto r = finish(start(d / "cap", {"validate", "--demo", "--demo-count", "100", "--runs", "2", "--seed", "3",
                                          "--out", (d / "out").string()}),
                        400);
  ASSERT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  const fs::path out = d / "out";
  const auto report = nlohmann::json::parse(slurp(out / "report.json"));
  EXPECT_EQ(report["sim_instances"].get<int>(), 100);
  EXPECT_EQ(report["real_instances"].get<int>(), 100);
  EXPECT_EQ(report["demo"]["block"].get<int>(), 40);  // the thesis's 5x5 grid
  ASSERT_EQ(report["analyses"].size(), 2u);
  EXPECT_EQ(report["analyses"]["regions"]["attributes"].get<int>(), 32);
  EXPECT_EQ(report["analyses"]["blocks"]["attributes"].get<int>(), 69);
  for (const char* key : {"regions", "blocks"}) {
    const auto& c = report["analyses"][key]["classifiers"];
    ASSERT_EQ(c.size(), 1u) << key;  // J48 alone by default
    const auto& j48 = c["J48"];
    for (const char* set : {"real", "sim", "combined"}) {
      SCOPED_TRACE(std::string(key) + " " + set);
      const double pct = j48[set]["mean_percent_correct"].get<double>();
      const double n = std::string(set) == "combined" ? 200 : 100;
      EXPECT_GT(pct, 60);  // case 2 is learnable, far above chance
      EXPECT_NEAR(j48[set]["mean_misclassified"].get<double>(), n * (100 - pct) / 100, 1e-6);
      // Each run's counts cover the set, its percentage is theirs, and the means are the runs'.
      const auto& runs = j48[set]["runs"];
      ASSERT_EQ(runs.size(), 2u);
      double pct_sum = 0;
      for (const auto& run : runs) {
        EXPECT_EQ(run["correct"].get<double>() + run["misclassified"].get<double>(), n);
        EXPECT_NEAR(run["percent_correct"].get<double>(), 100 * run["correct"].get<double>() / n, 1e-9);
        EXPECT_EQ(run["folds"].size(), report["folds"].get<size_t>());
        pct_sum += run["percent_correct"].get<double>();
      }
      EXPECT_NEAR(pct, pct_sum / 2, 1e-9);
    }
    EXPECT_GT(j48["sim_to_real"]["percent_correct"].get<double>(), 60) << key;
    // The P values belong to the runs' fold accuracies: each run's two-sample test on its
    // real and simulated folds, and the corrected test (t, df and P recomputed here) on
    // their differences, test/train = 1 / (k - 1) for k folds.
    double p_sum = 0;
    std::vector<double> d;
    for (size_t r = 0; r < 2; ++r) {
      const auto a = j48["real"]["runs"][r]["folds"].get<std::vector<double>>();
      const auto b = j48["sim"]["runs"][r]["folds"].get<std::vector<double>>();
      const auto two = portalsim::cli::student_two_sample(a, b);
      const auto& reported = j48["two_sample_t_test"]["per_run"][r];
      EXPECT_NEAR(reported["t"].get<double>(), two.t, 1e-9) << key << " run " << r;
      EXPECT_NEAR(reported["p"].get<double>(), two.p, 1e-9) << key << " run " << r;
      p_sum += two.p;
      for (size_t i = 0; i < a.size(); ++i) d.push_back(a[i] - b[i]);
    }
    EXPECT_NEAR(j48["two_sample_t_test"]["mean_p"].get<double>(), p_sum / 2, 1e-9) << key;
    double mean = 0, var = 0;
    for (double x : d) mean += x / static_cast<double>(d.size());
    for (double x : d) var += (x - mean) * (x - mean) / static_cast<double>(d.size() - 1);
    const auto& corrected = j48["corrected_resampled_t_test"];
    EXPECT_EQ(corrected["df"].get<double>(), static_cast<double>(d.size() - 1)) << key;
    if (var > 0) {
      const double ratio = 1.0 / (report["folds"].get<double>() - 1);
      const double t = mean / std::sqrt((1.0 / static_cast<double>(d.size()) + ratio) * var);
      EXPECT_NEAR(corrected["t"].get<double>(), t, 1e-9) << key;
      const double p = 2 * boost::math::cdf(boost::math::complement(
                               boost::math::students_t(static_cast<double>(d.size() - 1)), std::fabs(t)));
      EXPECT_NEAR(corrected["p"].get<double>(), p, 1e-9) << key;
    }
  }
  const std::string md = slurp(out / "report.md");
  for (const char* table : {"(as thesis table 6.1)", "(as thesis table 6.2)", "(as thesis table 6.5)",
                            "(as thesis table 6.6)", "## Sim-to-real", "(corrected resampled t-test, t = "})
    EXPECT_NE(md.find(table), std::string::npos) << table;
  EXPECT_GT(fs::file_size(out / "accuracy.png"), 1000u);
  EXPECT_GT(fs::file_size(out / "curve.png"), 1000u);

  // The real set comes through the user-image route: a catalogue naming altered images.
  const std::string catalogue = slurp(out / "demo" / "catalogue.toml");
  EXPECT_NE(catalogue.find("images.upper = \"images/subject1_upper.png\""), std::string::npos);
  EXPECT_NE(catalogue.find("images.lower = \"images/subject5_lower.png\""), std::string::npos);
  EXPECT_GT(fs::file_size(out / "demo" / "images" / "subject5_lower.png"), 1000u);
  const std::string sim = slurp(out / "demo" / "sim.arff"), real = slurp(out / "demo" / "real.arff");
  // The offset of +20 (gain 0.85) lifts the dark background of the altered views.
  EXPECT_GT(mean_of(real, "upper_r0_c0"), mean_of(sim, "upper_r0_c0") + 5);
  // The simulated set is exactly what generate makes of thesis case 2 with that seed.
  const auto g = finish(
      start(d / "cap", {"generate", "--spec", PORTALSIM_SOURCE_DIR "/scenarios/case2-rod-plate.toml", "--count", "100",
                        "--seed", "3", "--block", "40", "--format", "arff", "--out", (d / "g").string()}));
  ASSERT_TRUE(g.exited && g.status == 0) << portalsim::test::describe(g);
  EXPECT_EQ(sim, slurp(d / "g" / "features.arff"));
  // The "real" set is what generate makes of the same spec through the demo's catalogue.
  const auto h =
      finish(start(d / "cap", {"generate", "--spec", PORTALSIM_SOURCE_DIR "/scenarios/case2-rod-plate.toml",
                               "--catalogue", (out / "demo" / "catalogue.toml").string(), "--count", "100", "--seed",
                               "4", "--block", "40", "--format", "arff", "--out", (d / "h").string()}));
  ASSERT_TRUE(h.exited && h.status == 0) << portalsim::test::describe(h);
  EXPECT_EQ(real, slurp(d / "h" / "features.arff"));

  // --demo makes its own inputs; --sim or --real with it, or neither without it, is refused.
  const auto both = finish(start(d / "cap", {"validate", "--demo", "--sim", "x.arff", "--out", (d / "o2").string()}));
  expect_refused(both, 2, "--sim excludes --demo", d / "o2");  // 2: a usage error
  const auto none = finish(start(d / "cap", {"validate", "--out", (d / "o2").string()}));
  expect_refused(none, 3, "--sim and --real are both needed", d / "o2");
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
  spit(d / "text.csv", "a,b,class\n1,2,gun\n1,x,none\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"other.arff", "other.arff:3: attribute 'c' differs"},
      {"single.arff", "single value"},
      {"few.arff", "fewer than the 5 cross-validation folds"},
      {"text.csv", "text.csv:3: field 'b' is \"x\", not a number"},
      {"missing.arff", "missing.arff: no such file or folder"},
  };
  for (const auto& [file, message] : cases) {
    const auto r = validate(d, "ok.arff", file);
    expect_refused(r, 3, message, d / "out");
  }
  // No java on PATH: the run stops with a message instead of a report.
  const auto r = finish(portalsim::test::start_program(
      d / "cap", "/usr/bin/env",
      {"PATH=/nonexistent", portalsim::test::kBinary, "validate", "--sim", (d / "ok.arff").string(), "--real",
       (d / "ok.arff").string(), "--out", (d / "out").string(), "--folds", "5"}));
  expect_refused(r, 5, "java not found", d / "out");  // 5: the machine's environment
  fs::remove_all(d);
}

// The tables' fields go through the one CSV/ARFF reader (io/table_fields.h): a quoted field
// holds commas and blanks, in CSV "" is a quote, in ARFF '...' and \ escapes (issue 36).
TEST(ValidateTables, QuotedFieldsAreOneField) {
  using portalsim::cli::parse_arff;
  using portalsim::cli::parse_csv;
  std::istringstream csv("\"a,b\",c,class\n1,2,\"gun, \"\"loaded\"\"\"\n3,4,none\n");
  const portalsim::cli::Table c = parse_csv(csv, "t.csv");
  EXPECT_EQ(c.names, (std::vector<std::string>{"a,b", "c", "class"}));
  ASSERT_EQ(c.rows.size(), 2u);
  EXPECT_EQ(c.rows[0].back(), "gun, \"loaded\"");

  std::istringstream arff(
      "@relation t\n@attribute 'a b' numeric\n@ATTRIBUTE \"c,d\" numeric\n@attribute class {'it\\'s',none}\n"
      "@data\n1,2,'it\\'s'\n3,4,none\n");
  const portalsim::cli::Table a = parse_arff(arff, "t.arff");
  EXPECT_EQ(a.names, (std::vector<std::string>{"a b", "c,d", "class"}));
  EXPECT_EQ(a.name_lines, (std::vector<int>{2, 3, 4}));
  ASSERT_EQ(a.rows.size(), 2u);
  EXPECT_EQ(a.rows[0].back(), "it's");

  // Bad quoting is refused naming the file, line and column.
  const auto error = [](const std::string& text, bool is_csv) {
    std::istringstream in(text);
    try {
      (void)(is_csv ? parse_csv(in, "bad") : parse_arff(in, "bad"));
    } catch (const portalsim::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("a,b,class\n1,\"2,gun\n", true), "bad:2: column 2: a quoted field is not closed on its line");
  EXPECT_EQ(error("a,b,class\n1,2\"x\",gun\n", true),
            "bad:2: column 2: a quote inside an unquoted field: quote the whole field, and double each quote in it");
  EXPECT_EQ(error("@attribute 'a numeric\n@attribute class {x}\n@data\n", false),
            "bad:1: @attribute: a quoted field is not closed on its line");
}

TEST(TableFields, CsvAndArffQuoting) {
  using portalsim::io::Quoting;
  using portalsim::io::split_fields;
  EXPECT_EQ(split_fields(" a , \"b,c\" ,\"\"\"\",", Quoting::csv, "f", 1),
            (std::vector<std::string>{"a", "b,c", "\"", ""}));
  EXPECT_EQ(split_fields("'x,y',\"z\\\"\",w", Quoting::arff, "f", 1), (std::vector<std::string>{"x,y", "z\"", "w"}));
  EXPECT_EQ(split_fields("", Quoting::csv, "f", 1), (std::vector<std::string>{""}));
  const portalsim::io::ArffAttribute at = portalsim::io::arff_attribute("@attribute 'a b' {x, y}", "f", 1);
  EXPECT_EQ(at.name, "a b");
  EXPECT_EQ(at.type, "{x, y}");
}

}  // namespace
}  // namespace portalsim::test
