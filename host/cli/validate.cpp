// `portalsim validate`: the thesis's chapter 6 on a simulated and a real data set. Each is a
// feature table (ARFF or CSV) or a folder of scenario folders (turned into a table by the
// code of `portalsim features`). WEKA's J48, MultilayerPerceptron and SMO (default settings)
// are scored in one JVM (tools/WekaValidate.java, embedded) by cross-validation on real,
// simulated and combined data over several runs, trained on simulated data and tested on real
// data, and along a learning curve; the fold accuracies are compared by the thesis's t-test
// and by the corrected resampled t-test.
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

#include "base/error.h"
#include "cli/commands.h"
#include "cli/features_table.h"
#include "cli/validate_stats.h"
#include "sink/staging.h"

namespace portalsim::embedded {
extern const std::string_view weka_validate;
extern const std::string_view plot_validate;
}  // namespace portalsim::embedded

namespace portalsim::cli {

namespace {

namespace fs = std::filesystem;

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string unquote(std::string s) {
  if (s.size() >= 2 && (s[0] == '\'' || s[0] == '"') && s.back() == s[0]) return s.substr(1, s.size() - 2);
  return s;
}

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> f;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      f.push_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  f.push_back(trim(cur));
  return f;
}

// A feature table: numeric attributes, then the class (nominal) last.
struct Table {
  std::string path;
  std::vector<std::string> names;  // attribute names, class last
  std::vector<int> name_lines;     // where each is declared (1-based; the header row for CSV)
  std::vector<std::vector<std::string>> rows;
  std::set<std::string> classes;
};

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> f = split_commas(line);
  for (auto& v : f) v = unquote(v);
  return f;
}

void check_row(const std::string& path, int line, const Table& t, const std::vector<std::string>& f) {
  const std::string where = path + ":" + std::to_string(line);
  if (f.size() != t.names.size())
    throw InputError(where + ": instance has " + std::to_string(f.size()) + " values, the header declares " +
                     std::to_string(t.names.size()) + " attributes");
  for (size_t i = 0; i + 1 < f.size(); ++i) {
    if (f[i] == "?") continue;
    char* end = nullptr;
    std::strtod(f[i].c_str(), &end);
    if (f[i].empty() || *end != '\0')
      throw InputError(where + ": field '" + t.names[i] + "' is \"" + f[i] + "\", not a number");
  }
  if (f.back().empty() || f.back() == "?") throw InputError(where + ": field 'class' is missing");
}

// One data line, checked against the header and kept.
void add_row(Table& t, int line, const std::string& text) {
  std::vector<std::string> f = fields(text);
  check_row(t.path, line, t, f);
  t.classes.insert(f.back());
  t.rows.push_back(std::move(f));
}

std::ifstream open_table(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  return in;
}

Table read_arff(const std::string& path) {
  std::ifstream in = open_table(path);
  Table a;
  a.path = path;
  std::string line;
  bool data = false;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '%') continue;
    const std::string l = lower(t);
    if (!data) {
      if (l.rfind("@attribute", 0) == 0) {
        std::istringstream words(t.substr(10));
        std::string name;
        words >> name;
        a.names.push_back(unquote(name));
        a.name_lines.push_back(n);
      } else if (l.rfind("@data", 0) == 0) {
        data = true;
        if (a.names.size() < 2) throw InputError(path + ": needs at least one attribute and a class");
      }
      continue;
    }
    if (t[0] == '{') throw InputError(path + ":" + std::to_string(n) + ": sparse instances are not supported");
    add_row(a, n, t);
  }
  if (!data) throw InputError(path + ": no @data section");
  return a;
}

// CSV with a header row; the last column is the class.
Table read_csv(const std::string& path) {
  std::ifstream in = open_table(path);
  Table a;
  a.path = path;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (!a.names.empty()) {
      add_row(a, n, t);
      continue;
    }
    a.names = fields(t);
    a.name_lines.assign(a.names.size(), n);
    if (a.names.size() < 2)
      throw InputError(path + ":" + std::to_string(n) + ": needs at least one attribute and a class");
  }
  if (a.names.empty()) throw InputError(path + ": empty file, no header row");
  return a;
}

// A table file, or a folder of scenario folders made into one (in `work`) as `portalsim
// features` makes it.
Table load(const std::string& path, const std::string& work, const std::string& tag, int block,
           const std::string& catalogue) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const std::string table = (fs::path(work) / (".features-" + tag + ".arff")).string();
    const FeaturesCount n = write_features({path}, table, "arff", block, catalogue);
    std::fprintf(stderr, "validate: %s: %zu scenario folders\n", path.c_str(), n.rows);
    Table t = read_arff(table);
    t.path = path;
    return t;
  }
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file or folder");
  const std::string ext = lower(fs::path(path).extension().string());
  if (ext == ".arff") return read_arff(path);
  if (ext == ".csv") return read_csv(path);
  throw InputError(path + ": a feature table must be .arff or .csv, or a folder of scenario folders");
}

// Keeps the columns `features` asks for: "regions" drops the block means (VIEW_rY_cX),
// "blocks" drops the region means (regionN); the metal zones and the class stay.
void select_features(Table& t, const std::string& features) {
  if (features == "both") return;
  // "digits then `tail`" at the end of s, with at least one digit: returns where they start.
  const auto digits_before = [](std::string_view s, size_t end) {
    size_t b = end;
    while (b > 0 && s[b - 1] >= '0' && s[b - 1] <= '9') --b;
    return b < end ? b : std::string_view::npos;
  };
  const auto is_block = [&](std::string_view s) {  // .+_r[0-9]+_c[0-9]+
    const size_t c = digits_before(s, s.size());
    if (c == std::string_view::npos || c < 2 || s.substr(c - 2, 2) != "_c") return false;
    const size_t r = digits_before(s, c - 2);
    return r != std::string_view::npos && r >= 3 && s.substr(r - 2, 2) == "_r";
  };
  const auto is_region = [&](std::string_view s) {  // region[0-9]+
    return s.starts_with("region") && s.size() > 6 && digits_before(s, s.size()) == 6;
  };
  std::vector<size_t> keep;
  for (size_t i = 0; i < t.names.size(); ++i) {
    const bool drop = features == "regions" ? is_block(t.names[i]) : is_region(t.names[i]);
    if (i + 1 == t.names.size() || !drop) keep.push_back(i);
  }
  auto pick = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out;
    for (size_t i : keep) out.push_back(v[i]);
    v = std::move(out);
  };
  pick(t.names);
  pick(t.name_lines);
  for (auto& r : t.rows) pick(r);
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

void check_same_attributes(const Table& sim, const Table& real) {
  for (size_t i = 0; i < std::max(sim.names.size(), real.names.size()); ++i) {
    if (i < sim.names.size() && i < real.names.size() && lower(sim.names[i]) == lower(real.names[i])) continue;
    if (i >= real.names.size())
      throw InputError(sim.path + ":" + std::to_string(sim.name_lines[i]) + ": attribute '" + sim.names[i] +
                       "' has no counterpart in " + real.path);
    if (i >= sim.names.size())
      throw InputError(real.path + ":" + std::to_string(real.name_lines[i]) + ": attribute '" + real.names[i] +
                       "' has no counterpart in " + sim.path);
    throw InputError(real.path + ":" + std::to_string(real.name_lines[i]) + ": attribute '" + real.names[i] +
                     "' differs from " + sim.path + ":" + std::to_string(sim.name_lines[i]) + " '" + sim.names[i] +
                     "'");
  }
}

// The table as ARFF with a class declaration shared by both sets, so WEKA sees one header.
void write_arff(const Table& t, const std::set<std::string>& classes, const std::string& path) {
  std::string s = "@relation validate\n";
  auto q = [](const std::string& n) {
    std::string r = "'";
    for (char c : n) r += c == '\'' ? std::string("\\'") : std::string(1, c);
    return r + "'";
  };
  for (size_t i = 0; i + 1 < t.names.size(); ++i) s += "@attribute " + q(t.names[i]) + " numeric\n";
  s += "@attribute class {";
  bool first = true;
  for (const auto& c : classes) s += (first ? "" : ",") + q(c), first = false;
  s += "}\n@data\n";
  for (const auto& r : t.rows) {
    for (size_t i = 0; i + 1 < r.size(); ++i) s += r[i] + ",";
    s += q(r.back()) + "\n";
  }
  write_text_atomic(path, s);
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::istringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
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

// A scratch folder for the tables handed to WEKA, removed on every way out.
struct WorkDir {
  std::string path;
  WorkDir() {
    const char* tmp = std::getenv("TMPDIR");
    std::string tmpl = (fs::path(tmp && *tmp ? tmp : "/tmp") / "portalsim-validate-XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw EnvironmentError(tmpl + ": cannot create a scratch folder");
    path = tmpl;
  }
  ~WorkDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  WorkDir(const WorkDir&) = delete;
  WorkDir& operator=(const WorkDir&) = delete;
};

struct Options {
  std::string sim, real, out, features = "both", classifiers = "j48,mlp,svm", catalogue, grid;
  int folds = 10, runs = 10, seed = 1, block = 10, curve_steps = 4;
};

int run_validate(Options o) {
  if (!o.grid.empty()) o.block = block_for_grid(o.grid, o.catalogue);
  const char* jar = "/usr/share/java/weka.jar";
  if (!fs::exists(jar)) throw EnvironmentError(std::string(jar) + " not found (apt-get install weka)");
  if (!on_path("java")) throw EnvironmentError("java not found on PATH (apt-get install default-jdk-headless)");
  std::vector<std::string> names;
  for (const std::string& c : split_commas(lower(o.classifiers))) {
    if (std::none_of(kClassifiers.begin(), kClassifiers.end(), [&](const auto& k) { return k.first == c; }))
      throw InputError("--classifiers: unknown classifier '" + c + "' (j48, mlp or svm)");
    names.push_back(c);
  }

  const WorkDir scratch;
  const std::string& work = scratch.path;
  Table sim = load(o.sim, work, "sim", o.block, o.catalogue);
  Table real = load(o.real, work, "real", o.block, o.catalogue);
  select_features(sim, o.features);
  select_features(real, o.features);
  check_same_attributes(sim, real);
  check_usable(sim, o.folds);
  check_usable(real, o.folds);
  std::set<std::string> classes = sim.classes;
  classes.insert(real.classes.begin(), real.classes.end());
  const std::string sim_arff = (fs::path(work) / ".sim.arff").string();
  const std::string real_arff = (fs::path(work) / ".real.arff").string();
  write_arff(sim, classes, sim_arff);
  write_arff(real, classes, real_arff);

  // All the WEKA work in one JVM.
  const std::string program = (fs::path(work) / "WekaValidate.java").string();
  const std::string weka_out = (fs::path(work) / ".weka.json").string();
  write_text_atomic(program, std::string(embedded::weka_validate));
  std::string classifiers;
  for (const auto& n : names) classifiers += (classifiers.empty() ? "" : ",") + n;
  const std::string cmd = "java -Xmx2g -cp " + std::string(jar) + " " + shell_quote(program) + " --real " +
                          shell_quote(real_arff) + " --sim " + shell_quote(sim_arff) + " --folds " +
                          std::to_string(o.folds) + " --runs " + std::to_string(o.runs) + " --seed " +
                          std::to_string(o.seed) + " --classifiers " + classifiers + " --curve-steps " +
                          std::to_string(o.curve_steps) + " > " + shell_quote(weka_out);
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("WEKA failed (its messages are above)");
  nlohmann::json weka;
  {
    std::ifstream in(weka_out);
    weka = nlohmann::json::parse(in);
  }

  StagedFolder folder(o.out);
  nlohmann::json report = {{"sim", o.sim},
                           {"real", o.real},
                           {"folds", o.folds},
                           {"runs", o.runs},
                           {"seed", o.seed},
                           {"features", o.features},
                           {"attributes", sim.names.size() - 1},
                           {"sim_instances", sim.rows.size()},
                           {"real_instances", real.rows.size()}};
  std::ostringstream md, trees, tests;
  md << "# portalsim validate\n\nSimulated: `" << o.sim << "` (" << sim.rows.size() << " instances), real: `" << o.real
     << "` (" << real.rows.size() << " instances); " << sim.names.size() - 1 << " attributes and the class ("
     << o.features << " features); " << o.folds << "-fold stratified cross-validation as WEKA's `-x " << o.folds
     << " -s SEED`, " << o.runs << " run(s) with seeds " << o.seed << ".." << o.seed + o.runs - 1 << ".\n\n"
     << "## Accuracy (thesis tables 6.1-6.7 layout; mean over runs)\n\n"
     << "| Classifier | Real: % correct | Real: misclassified | Simulated: % correct | Simulated: misclassified | "
        "Combined: % correct | Combined: misclassified | Sim-to-real: % correct | Sim-to-real: misclassified |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  tests << "## Real against simulated fold accuracies\n\n"
        << "| Classifier | Two-sample t-test (Student, pooled variance, two-tailed; thesis table 6.8), mean P over "
           "runs | Corrected resampled t-test (Nadeau & Bengio 2003, as WEKA's Experimenter), P |\n"
        << "|---|---|---|\n";
  std::ostringstream claim;
  claim
      << "## The thesis's combined-data claim\n\nThe thesis claims that combined (real + simulated) data has fewer "
         "misclassifications than real and simulated data together (sum of their misclassified counts).\n\n"
      << "| Classifier | Real + simulated misclassified | Combined misclassified | Claim holds |\n|---|---|---|---|\n";
  std::ostringstream curve_md;
  curve_md << "## Learning curve\n\nReal data in " << o.folds
           << " stratified folds; simulated scenarios added to each training fold; % correct on the held-out real "
              "instances (seed "
           << o.seed << ").\n\n";
  if (o.curve_steps == 0) curve_md << "Not computed (`--curve-steps 0`).\n\n";

  for (const auto& [key, label] : kClassifiers) {
    if (std::find(names.begin(), names.end(), key) == names.end()) continue;
    const auto& w = weka["classifiers"][key];
    nlohmann::json c;
    double mean_pct[3] = {0, 0, 0}, mean_wrong[3] = {0, 0, 0};
    const char* sets[3] = {"real", "sim", "combined"};
    for (int s = 0; s < 3; ++s) {
      for (const auto& run : w[sets[s]]) {
        mean_pct[s] += run["percent_correct"].get<double>() / o.runs;
        mean_wrong[s] += run["misclassified"].get<double>() / o.runs;
      }
      c[sets[s]] = {{"runs", w[sets[s]]}, {"mean_percent_correct", mean_pct[s]}, {"mean_misclassified", mean_wrong[s]}};
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
    const double together = mean_wrong[0] + mean_wrong[1];
    c["combined_claim"] = {{"real_plus_sim_misclassified", together},
                           {"combined_misclassified", mean_wrong[2]},
                           {"holds", mean_wrong[2] < together}};
    md << "| " << label << " | " << fmt(mean_pct[0]) << " | " << fmt(mean_wrong[0], 1) << " | " << fmt(mean_pct[1])
       << " | " << fmt(mean_wrong[1], 1) << " | " << fmt(mean_pct[2]) << " | " << fmt(mean_wrong[2], 1) << " | "
       << fmt(w["sim_to_real"]["percent_correct"].get<double>()) << " | "
       << w["sim_to_real"]["misclassified"].get<long>() << " |\n";
    tests << "| " << label << " | P = " << fmt_p(p_sum / o.runs) << " (two-sample t-test) | P = " << fmt_p(corrected.p)
          << " (corrected resampled t-test, t = " << fmt(corrected.t, 3) << ", df = " << corrected.df << ") |\n";
    claim << "| " << label << " | " << fmt(together, 1) << " | " << fmt(mean_wrong[2], 1) << " | "
          << (mean_wrong[2] < together ? "yes" : "no") << " |\n";
    if (w.contains("curve")) {
      curve_md << "| " << label << " | sim added | % correct |\n|---|---|---|\n";
      for (const auto& p : w["curve"])
        curve_md << "| | " << p["sim_added"].get<long>() << " | " << fmt(p["percent_correct"].get<double>()) << " |\n";
      curve_md << "\n";
    }
    if (w.contains("trees")) {
      c["trees"] = w["trees"];
      trees << "## J48 trees (thesis figures 6.10-6.12)\n\n";
      for (const char* s : sets) trees << "### " << s << "\n\n```\n" << w["trees"][s].get<std::string>() << "```\n\n";
    }
    report["classifiers"][label] = c;
  }
  md << "\n"
     << tests.str() << "\nP > 0.05: the fold accuracies do not tell real from simulated data.\n\n"
     << claim.str() << "\n"
     << curve_md.str() << trees.str() << "## Plots\n\n![accuracy](accuracy.png)\n\n![learning curve](curve.png)\n";
  write_text_atomic(folder.path("report.md"), md.str());
  write_text_atomic(folder.path("report.json"), report.dump(2) + "\n");

  // The plots, drawn by the embedded matplotlib script from report.json in the staging folder.
  const std::string script = (fs::path(work) / "plot_validate.py").string();
  write_text_atomic(script, std::string(embedded::plot_validate));
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  if (std::system((python + " " + shell_quote(script) + " " + shell_quote(folder.dir())).c_str()) != 0)
    throw OutputError("accuracy.png: the plot failed (python3 with matplotlib is needed)");
  folder.path("accuracy.png");
  folder.path("curve.png");
  folder.commit();
  std::printf("%s", md.str().c_str());
  return 0;
}

}  // namespace

std::function<int()> add_validate(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("validate", "Score simulated against real data with WEKA (thesis ch. 6)");
  cmd->add_option("--sim", o->sim, "Simulated data: feature table (ARFF or CSV) or folder of scenario folders")
      ->required();
  cmd->add_option("--real", o->real, "Real data: feature table (ARFF or CSV) or folder of scenario folders")
      ->required();
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
  return [o]() { return run_validate(*o); };
}

}  // namespace portalsim::cli
