// `portalsim validate`: the thesis's chapter 6 on a simulated and a real data set. Each is a
// feature table (ARFF, CSV or a data.h5 of `generate --format h5`) or a folder of scenario
// folders (turned into a table by the code of `portalsim features`). WEKA's J48, MultilayerPerceptron and SMO (default
// settings) are scored in one JVM (tools/Weka.java, embedded) by cross-validation on real, simulated and
// combined data over several runs, trained on simulated data and tested on real data, and along a learning curve; the
// fold accuracies are compared by the thesis's t-test and by the corrected resampled t-test.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "base/embedded.h"
#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/features_table.h"
#include "cli/learning_sets.h"
#include "cli/validate_demo.h"
#include "cli/validate_stats.h"
#include "cli/validate_tables.h"
#include "cli/weka.h"
#include "sink/feature_rows.h"
#include "sink/h5_file.h"
#include "sink/staging.h"

namespace portalsim::cli {

namespace {

namespace fs = std::filesystem;

bool has_column(const Table& t, bool (*kind)(std::string_view)) {
  return std::any_of(t.names.begin(), t.names.end(), [&](const std::string& n) { return kind(n); });
}

// The table with the columns of one analysis: "regions" drops the block means, "blocks"
// the region means, "all" nothing; the class stays last.
Table select_features(const Table& t, const std::string& set) {
  if (set == "all") return t;
  std::vector<size_t> keep;
  for (size_t i = 0; i < t.names.size(); ++i) {
    const bool drop = set == "regions" ? is_block(t.names[i]) : is_region(t.names[i]);
    if (i + 1 == t.names.size() || !drop) keep.push_back(i);
  }
  Table out;
  out.path = t.path;
  out.classes = t.classes;
  for (size_t i : keep) {
    out.names.push_back(t.names[i]);
    out.name_lines.push_back(t.name_lines[i]);
  }
  out.rows.reserve(t.rows.size());
  for (const auto& r : t.rows) {
    std::vector<std::string> row;
    row.reserve(keep.size());
    for (size_t i : keep) row.push_back(r[i]);
    out.rows.push_back(std::move(row));
  }
  return out;
}

// The analyses `--features` asks for. "both" is the regions and the blocks analyses, as the
// thesis ran them; a table without both kinds of column gets one analysis of all columns.
std::vector<std::string> analyses_for(const std::string& features, const Table& sim) {
  const bool regions = has_column(sim, is_region), blocks = has_column(sim, is_block);
  if (features == "both")
    return regions && blocks ? std::vector<std::string>{"regions", "blocks"} : std::vector<std::string>{"all"};
  if (features == "regions" && !regions)
    throw InputError(sim.path + ": --features regions: no region-mean attributes (region1, region2, ...)");
  if (features == "blocks" && !blocks)
    throw InputError(sim.path + ": --features blocks: no block-mean attributes (VIEW_rY_cX)");
  return {features};
}

void check_usable(const Table& a, int folds) {
  if (a.classes.size() < 2)
    throw InputError(a.path + ": class attribute '" + a.names.back() + "' has a single value in the data (" +
                     (a.classes.empty() ? std::string("none") : *a.classes.begin()) +
                     "); validation needs at least two classes");
  if (a.rows.size() < static_cast<size_t>(folds))
    throw InputError(a.path + ": " + std::to_string(a.rows.size()) + " instances, fewer than the " +
                     std::to_string(folds) + " cross-validation folds");
}

const std::vector<std::pair<std::string, std::string>> kClassifiers = {
    {"j48", "J48"}, {"mlp", "MultilayerPerceptron"}, {"svm", "SMO"}};

std::string fmt(double v, int digits = 2) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

std::string fmt_p(double p) {
  char b[64];
  std::snprintf(b, sizeof b, p < 0.001 ? "%.2g" : "%.3f", p);
  return b;
}

struct Options {
  std::string sim, real, out, features = "both", classifiers = "j48,mlp,svm", catalogue, grid;
  int folds = 10, runs = 10, seed = 1, block = 10, curve_steps = 4;
  bool demo = false;
  uint64_t demo_count = kDemoCount;
};

// What the report calls an analysis, and the thesis tables of its real, simulated and
// combined data.
struct FeatureSet {
  std::string title;
  std::vector<std::string> tables;
};

FeatureSet feature_set(const std::string& key) {
  if (key == "regions") return {"region means", {"6.1", "6.3", "6.5"}};
  if (key == "blocks") return {"block means", {"6.2", "6.4", "6.6"}};
  return {"all attributes", {}};
}

constexpr const char* kSets[3] = {"real", "sim", "combined"};

// All the WEKA work of one analysis in one JVM; returns tools/Weka.java's JSON.
nlohmann::json run_weka(const Options& o, const std::string& classifiers, const std::string& work,
                        const std::string& key, const Table& sim, const Table& real) {
  std::set<std::string> classes = sim.classes;
  classes.insert(real.classes.begin(), real.classes.end());
  const std::string sim_arff = (fs::path(work) / (".sim-" + key + ".arff")).string();
  const std::string real_arff = (fs::path(work) / (".real-" + key + ".arff")).string();
  write_arff(sim, classes, sim_arff);
  write_arff(real, classes, real_arff);
  const std::string weka_out = (fs::path(work) / (".weka-" + key + ".json")).string();
  std::fprintf(stderr, "validate: %s (%s, %zu attributes)\n", key.c_str(), feature_set(key).title.c_str(),
               sim.names.size() - 1);
  const std::string cmd = weka_command(work, "2g") + " --real " + shell_quote(real_arff) + " --sim " +
                          shell_quote(sim_arff) + " --folds " + std::to_string(o.folds) + " --runs " +
                          std::to_string(o.runs) + " --seed " + std::to_string(o.seed) + " --classifiers " +
                          classifiers + " --curve-steps " + std::to_string(o.curve_steps) + " > " +
                          shell_quote(weka_out);
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("WEKA failed (its messages are above)");
  std::ifstream in(weka_out);
  return nlohmann::json::parse(in);
}

// One classifier's scores in one analysis: means over runs, both t-tests, sim-to-real, the
// learning curve and the combined-data claim.
nlohmann::json score(const Options& o, const nlohmann::json& w) {
  nlohmann::json c;
  double wrong[3] = {0, 0, 0};
  for (int s = 0; s < 3; ++s) {
    double pct = 0;
    for (const auto& run : w[kSets[s]]) {
      pct += run["percent_correct"].get<double>() / o.runs;
      wrong[s] += run["misclassified"].get<double>() / o.runs;
    }
    c[kSets[s]] = {{"runs", w[kSets[s]]}, {"mean_percent_correct", pct}, {"mean_misclassified", wrong[s]}};
  }
  // The thesis's test per run, averaged; the corrected test over all runs x folds.
  double p_sum = 0;
  std::vector<double> differences;
  nlohmann::json per_run = nlohmann::json::array();
  for (int r = 0; r < o.runs; ++r) {
    const auto a = w["real"][r]["folds"].get<std::vector<double>>();
    const auto b = w["sim"][r]["folds"].get<std::vector<double>>();
    const TTest t = student_two_sample(a, b);
    p_sum += t.p;
    per_run.push_back({{"t", t.t}, {"df", t.df}, {"p", t.p}});
    for (size_t i = 0; i < a.size(); ++i) differences.push_back(a[i] - b[i]);
  }
  const TTest corrected = corrected_resampled(differences, 1.0 / (o.folds - 1));
  c["two_sample_t_test"] = {{"test", "Student two-sample t-test, pooled variance, two-tailed (thesis table 6.8)"},
                            {"per_run", per_run},
                            {"mean_p", p_sum / o.runs}};
  c["corrected_resampled_t_test"] = {{"test", "corrected resampled t-test (Nadeau & Bengio 2003)"},
                                     {"t", corrected.t},
                                     {"df", corrected.df},
                                     {"p", corrected.p}};
  c["sim_to_real"] = w["sim_to_real"];
  if (w.contains("curve")) c["learning_curve"] = w["curve"];
  if (w.contains("trees")) c["trees"] = w["trees"];
  const double together = wrong[0] + wrong[1];
  c["combined_claim"] = {
      {"real_plus_sim_misclassified", together}, {"combined_misclassified", wrong[2]}, {"holds", wrong[2] < together}};
  return c;
}

// The analyses in the thesis's order (regions before blocks); JSON objects sort by key.
std::vector<std::pair<std::string, nlohmann::json>> in_order(const nlohmann::json& analyses) {
  std::vector<std::pair<std::string, nlohmann::json>> v;
  for (const char* key : {"regions", "blocks", "all"})
    if (analyses.contains(key)) v.emplace_back(key, analyses[key]);
  return v;
}

// report.md from report.json: the thesis's tables 6.1-6.6 (one per data set and feature
// set), then sim-to-real, the t-tests (table 6.8), the combined claim, curves and trees.
std::string markdown(const Options& o, const nlohmann::json& report) {
  const auto& analyses = report["analyses"];
  const auto title = [](const std::string& key) { return feature_set(key).title; };
  std::ostringstream md;
  md << "# portalsim validate\n\nSimulated: `" << report["sim"].get<std::string>() << "` ("
     << report["sim_instances"].get<size_t>() << " instances), real: `" << report["real"].get<std::string>() << "` ("
     << report["real_instances"].get<size_t>() << " instances); " << o.folds
     << "-fold stratified cross-validation as WEKA's `-x " << o.folds << " -s SEED`, " << o.runs
     << " run(s) with seeds " << o.seed << ".." << o.seed + o.runs - 1 << ". Feature sets (`--features " << o.features
     << "`): ";
  std::string sets;
  for (const auto& [key, a] : in_order(analyses))
    sets += (sets.empty() ? "" : "; ") + title(key) + " (" + std::to_string(a["attributes"].get<size_t>()) +
            " attributes and the class)";
  md << sets << ".\n\n## Data and features (thesis tables 6.1-6.6 layout; mean over runs)\n\n";
  const char* set_names[3] = {"Real data", "Simulated data", "Combined data"};
  for (int s = 0; s < 3; ++s)
    for (const auto& [key, a] : in_order(analyses)) {
      const FeatureSet f = feature_set(key);
      md << "### " << set_names[s] << ", " << f.title;
      if (!f.tables.empty()) md << " (as thesis table " << f.tables[s] << ")";
      md << "\n\n| Classification algorithm | Classification accuracy (%) | Misclassified instances |\n|---|---|---|\n";
      for (const auto& [label, c] : a["classifiers"].items())
        md << "| " << label << " | " << fmt(c[kSets[s]]["mean_percent_correct"].get<double>()) << " | "
           << fmt(c[kSets[s]]["mean_misclassified"].get<double>(), 1) << " |\n";
      md << "\n";
    }
  md << "## Sim-to-real: trained on simulated data, tested on real data\n\n"
     << "| Classifier | Feature set | % correct | Misclassified |\n|---|---|---|---|\n";
  for (const auto& [key, a] : in_order(analyses))
    for (const auto& [label, c] : a["classifiers"].items())
      md << "| " << label << " | " << title(key) << " | " << fmt(c["sim_to_real"]["percent_correct"].get<double>())
         << " | " << c["sim_to_real"]["misclassified"].get<long>() << " |\n";
  md << "\n## Real against simulated fold accuracies\n\n"
     << "| Classifier | Feature set | Two-sample t-test (Student, pooled variance, two-tailed; thesis table 6.8), "
        "mean P over runs | Corrected resampled t-test (Nadeau & Bengio 2003, as WEKA's Experimenter), P |\n"
     << "|---|---|---|---|\n";
  for (const auto& [key, a] : in_order(analyses))
    for (const auto& [label, c] : a["classifiers"].items()) {
      const auto& t = c["corrected_resampled_t_test"];
      md << "| " << label << " | " << title(key) << " | P = " << fmt_p(c["two_sample_t_test"]["mean_p"].get<double>())
         << " (two-sample t-test) | P = " << fmt_p(t["p"].get<double>())
         << " (corrected resampled t-test, t = " << fmt(t["t"].get<double>(), 3) << ", df = " << t["df"].get<double>()
         << ") |\n";
    }
  md << "\nP > 0.05: the fold accuracies do not tell real from simulated data.\n\n"
     << "## The thesis's combined-data claim\n\nThe thesis claims that combined (real + simulated) data has fewer "
        "misclassifications than real and simulated data together (sum of their misclassified counts).\n\n"
     << "| Classifier | Feature set | Real + simulated misclassified | Combined misclassified | Claim holds |\n"
     << "|---|---|---|---|---|\n";
  for (const auto& [key, a] : in_order(analyses))
    for (const auto& [label, c] : a["classifiers"].items()) {
      const auto& cl = c["combined_claim"];
      md << "| " << label << " | " << title(key) << " | " << fmt(cl["real_plus_sim_misclassified"].get<double>(), 1)
         << " | " << fmt(cl["combined_misclassified"].get<double>(), 1) << " | "
         << (cl["holds"].get<bool>() ? "yes" : "no") << " |\n";
    }
  md << "\n## Learning curve\n\nReal data in " << o.folds
     << " stratified folds; simulated scenarios added to each training fold; % correct on the held-out real "
        "instances (seed "
     << o.seed << ").\n\n";
  if (o.curve_steps == 0) md << "Not computed (`--curve-steps 0`).\n\n";
  for (const auto& [key, a] : in_order(analyses))
    for (const auto& [label, c] : a["classifiers"].items()) {
      if (!c.contains("learning_curve")) continue;
      md << "| " << label << ", " << title(key) << " | sim added | % correct |\n|---|---|---|\n";
      for (const auto& p : c["learning_curve"])
        md << "| | " << p["sim_added"].get<long>() << " | " << fmt(p["percent_correct"].get<double>()) << " |\n";
      md << "\n";
    }
  for (const auto& [key, a] : in_order(analyses))
    for (const auto& [label, c] : a["classifiers"].items()) {
      if (!c.contains("trees")) continue;
      md << "## J48 trees, " << title(key) << " (thesis figures 6.10-6.12)\n\n";
      for (const char* s : kSets) md << "### " << s << "\n\n```\n" << c["trees"][s].get<std::string>() << "```\n\n";
    }
  md << "## Plots\n\n![accuracy](accuracy.png)\n\n![learning curve](curve.png)\n";
  return md.str();
}

int run_validate(Options o) {
  if (!o.grid.empty()) o.block = block_for_grid(o.grid, o.catalogue);
  if (const auto missing = weka_missing()) throw EnvironmentError(*missing);
  std::string classifiers;
  for (const std::string& c : split_commas(lower(o.classifiers))) {
    if (std::none_of(kClassifiers.begin(), kClassifiers.end(), [&](const auto& k) { return k.first == c; }))
      throw InputError("--classifiers: unknown classifier '" + c + "' (j48, mlp or svm)");
    classifiers += (classifiers.empty() ? "" : ",") + c;
  }

  const WorkDir scratch;
  const std::string& work = scratch.path;
  StagedFolder folder(o.out);
  std::string sim_path = o.sim, real_path = o.real;
  nlohmann::json demo;
  if (o.demo) {
    // The inputs are made here and kept beside the report, under demo/.
    const std::string demo_dir = folder.path("demo");
    demo = make_demo_sets(demo_dir, o.demo_count, static_cast<uint64_t>(o.seed), o.block);
    sim_path = demo["sim"].get<std::string>();
    real_path = demo["real"].get<std::string>();
    o.sim = (fs::path(o.out) / "demo" / fs::path(sim_path).filename()).string();
    o.real = (fs::path(o.out) / "demo" / fs::path(real_path).filename()).string();
  }
  const Table sim = load_table(sim_path, work, "sim", o.block, o.catalogue);
  const Table real = load_table(real_path, work, "real", o.block, o.catalogue);

  nlohmann::json report = {{"sim", o.sim},
                           {"real", o.real},
                           {"folds", o.folds},
                           {"runs", o.runs},
                           {"seed", o.seed},
                           {"features", o.features},
                           {"sim_instances", sim.rows.size()},
                           {"real_instances", real.rows.size()}};
  if (o.demo) report["demo"] = demo["about"];
  // Check every analysis before the slow part starts.
  std::vector<std::pair<std::string, std::pair<Table, Table>>> sets;
  for (const std::string& key : analyses_for(o.features, sim)) {
    Table s = select_features(sim, key), r = select_features(real, key);
    check_same_attributes(s, r);
    check_usable(s, o.folds);
    check_usable(r, o.folds);
    sets.emplace_back(key, std::make_pair(std::move(s), std::move(r)));
  }
  for (const auto& [key, tables] : sets) {
    const nlohmann::json weka = run_weka(o, classifiers, work, key, tables.first, tables.second);
    nlohmann::json a = {{"feature_set", feature_set(key).title}, {"attributes", tables.first.names.size() - 1}};
    if (!feature_set(key).tables.empty()) a["thesis_tables"] = feature_set(key).tables;
    for (const auto& [name, label] : kClassifiers)
      if (weka["classifiers"].contains(name)) a["classifiers"][label] = score(o, weka["classifiers"][name]);
    report["analyses"][key] = a;
  }
  const std::string md = markdown(o, report);
  write_text_atomic(folder.path("report.md"), md);
  write_text_atomic(folder.path("report.json"), report.dump(2) + "\n");

  // The plots, drawn by the embedded matplotlib script from report.json in the staging folder.
  run_plot_script(embedded::plot_validate, folder.dir(), {folder.dir()}, "accuracy.png", false);
  folder.path("accuracy.png");
  folder.path("curve.png");
  folder.commit();
  std::printf("%s", md.c_str());
  return 0;
}

}  // namespace

std::function<int()> add_validate(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("validate", "Score simulated against real data with WEKA (thesis ch. 6)");
  auto* sim = cmd->add_option("--sim", o->sim,
                              "Simulated data: feature table (ARFF, CSV or data.h5) or folder of scenario folders");
  auto* real = cmd->add_option("--real", o->real,
                               "Real data: feature table (ARFF, CSV or data.h5) or folder of scenario folders");
  auto* demo = cmd->add_flag("--demo", o->demo,
                             "No real data to hand: make a simulated and an altered-image \"real\" set (thesis case "
                             "2) and validate them; both are kept under OUT/demo/")
                   ->excludes(sim)
                   ->excludes(real);
  cmd->add_option("--demo-count", o->demo_count,
                  "Scenarios per --demo set (default " + std::to_string(kDemoCount) + ")")
      ->check(CLI::Range(uint64_t{20}, uint64_t{100000}))
      ->needs(demo);
  cmd->add_option("--out", o->out, "Folder for report.md, report.json and the plots")->required();
  cmd->add_option("--features", o->features, "regions, blocks or both (default both)")
      ->check(CLI::IsMember({"regions", "blocks", "both"}));
  auto* block = cmd->add_option("--block", o->block, "Block side for folders turned into tables (default 10)");
  cmd->add_option("--grid", o->grid, "WxH blocks per view instead of --block (5x5: the thesis's grid)")
      ->excludes(block);
  cmd->add_option("--catalogue", o->catalogue, "Catalogue TOML for folders turned into tables");
  cmd->add_option("--classifiers", o->classifiers, "Comma-separated: j48, mlp, svm (default all three)");
  cmd->add_option("--folds", o->folds, "Cross-validation folds (default 10)")->check(CLI::Range(2, 1000));
  cmd->add_option("--runs", o->runs, "Cross-validation runs, seeds SEED.. SEED+RUNS-1 (default 10)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--seed", o->seed, "Seed of the first run (default 1)");
  cmd->add_option("--curve-steps", o->curve_steps, "Learning-curve points after the first; 0: none (default 4)")
      ->check(CLI::Range(0, 100));
  return [o, cmd]() {
    if (!o->demo && (o->sim.empty() || o->real.empty()))
      throw InputError("validate: --sim and --real are both needed (or --demo, to see a report without real data)");
    // The demo's default keeps it short: J48 alone (MultilayerPerceptron takes minutes).
    if (o->demo && cmd->get_option("--classifiers")->count() == 0) o->classifiers = "j48";
    // and the thesis's 5x5 grid of block means (appendix D.4) unless --block or --grid says otherwise.
    if (o->demo && cmd->get_option("--block")->count() == 0 && o->grid.empty()) o->grid = "5x5";
    return run_validate(*o);
  };
}

}  // namespace portalsim::cli
