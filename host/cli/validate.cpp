// `portalsim validate`: the thesis's chapter 6 on two feature tables. WEKA's J48,
// MultilayerPerceptron and SMO (default settings) are scored by cross-validation on the
// real and the simulated set, and trained on simulated data and tested on real data.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "base/error.h"
#include "cli/commands.h"
#include "cli/weka.h"
#include "sink/staging.h"

namespace portalsim::cli {

namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct Arff {
  std::vector<std::string> attributes;  // the @attribute lines, trimmed
  std::vector<int> attribute_lines;
  std::set<std::string> classes;  // class values present in the data
  size_t instances = 0;
};

// Reads what validate checks before handing the file to WEKA; errors name file and line.
Arff read_arff(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  Arff a;
  std::string line;
  bool data = false;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '%') continue;
    const std::string l = lower(t);
    if (!data) {
      if (l.rfind("@attribute", 0) == 0) {
        a.attributes.push_back(t);
        a.attribute_lines.push_back(n);
      } else if (l.rfind("@data", 0) == 0) {
        data = true;
      }
      continue;
    }
    if (t[0] == '{') throw InputError(path + ":" + std::to_string(n) + ": sparse instances are not supported");
    const size_t comma = t.rfind(',');
    const size_t fields = static_cast<size_t>(std::count(t.begin(), t.end(), ',')) + 1;
    if (fields != a.attributes.size())
      throw InputError(path + ":" + std::to_string(n) + ": instance has " + std::to_string(fields) +
                       " values, the header declares " + std::to_string(a.attributes.size()) + " attributes");
    a.classes.insert(trim(comma == std::string::npos ? t : t.substr(comma + 1)));
    ++a.instances;
  }
  if (!data) throw InputError(path + ": no @data section");
  if (a.attributes.size() < 2) throw InputError(path + ": needs at least one attribute and a class");
  return a;
}

void check_usable(const std::string& path, const Arff& a, int folds) {
  if (a.classes.size() < 2)
    throw InputError(path + ": class attribute (" + a.attributes.back() + ") has a single value in the data (" +
                     (a.classes.empty() ? std::string("none") : *a.classes.begin()) +
                     "); validation needs at least two classes");
  if (a.instances < static_cast<size_t>(folds))
    throw InputError(path + ": " + std::to_string(a.instances) + " instances, fewer than the " + std::to_string(folds) +
                     " cross-validation folds");
}

void check_same_attributes(const std::string& sim_path, const Arff& sim, const std::string& real_path,
                           const Arff& real) {
  for (size_t i = 0; i < std::max(sim.attributes.size(), real.attributes.size()); ++i) {
    if (i < sim.attributes.size() && i < real.attributes.size() &&
        lower(sim.attributes[i]) == lower(real.attributes[i]))
      continue;
    if (i >= real.attributes.size())
      throw InputError(sim_path + ":" + std::to_string(sim.attribute_lines[i]) + ": attribute '" + sim.attributes[i] +
                       "' has no counterpart in " + real_path);
    if (i >= sim.attributes.size())
      throw InputError(real_path + ":" + std::to_string(real.attribute_lines[i]) + ": attribute '" +
                       real.attributes[i] + "' has no counterpart in " + sim_path);
    throw InputError(real_path + ":" + std::to_string(real.attribute_lines[i]) + ": attribute '" + real.attributes[i] +
                     "' differs from " + sim_path + ":" + std::to_string(sim.attribute_lines[i]) + " '" +
                     sim.attributes[i] + "'");
  }
}

const std::vector<std::pair<std::string, std::string>> kClassifiers = {
    {"J48", "weka.classifiers.trees.J48"},
    {"MultilayerPerceptron", "weka.classifiers.functions.MultilayerPerceptron"},
    {"SMO", "weka.classifiers.functions.SMO"},
};

}  // namespace

std::function<int()> add_validate(CLI::App& app) {
  struct Options {
    std::string sim, real, out;
    int folds = 10, seed = 1;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("validate", "Score simulated against real feature tables with WEKA (thesis ch. 6)");
  cmd->add_option("--sim", o->sim, "Simulated feature table (ARFF)")->required();
  cmd->add_option("--real", o->real, "Real feature table (ARFF)")->required();
  cmd->add_option("--out", o->out, "Folder for report.md and report.json")->required();
  cmd->add_option("--folds", o->folds, "Cross-validation folds")->check(CLI::Range(2, 1000));
  cmd->add_option("--seed", o->seed, "Cross-validation seed");
  return [o]() {
    const Arff sim = read_arff(o->sim), real = read_arff(o->real);
    check_same_attributes(o->sim, sim, o->real, real);
    check_usable(o->sim, sim, o->folds);
    check_usable(o->real, real, o->folds);
    nlohmann::json report = {{"sim", o->sim}, {"real", o->real}, {"folds", o->folds}, {"seed", o->seed}};
    std::ostringstream md;
    md << "# portalsim validate\n\nSimulated: `" << o->sim << "` (" << sim.instances << " instances), real: `"
       << o->real << "` (" << real.instances << " instances), " << sim.attributes.size() << " attributes, " << o->folds
       << "-fold stratified cross-validation, seed " << o->seed << ".\n\n"
       << "| Classifier | Real: % correct | Real: misclassified | Simulated: % correct | Simulated: "
          "misclassified | Sim-to-real: % correct | Sim-to-real: misclassified |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (const auto& [name, cls] : kClassifiers) {
      std::fprintf(stderr, "validate: %s\n", name.c_str());
      std::string why;
      const auto on_real = weka_score(cls, o->real, "", o->folds, o->seed, why);
      const auto on_sim = on_real ? weka_score(cls, o->sim, "", o->folds, o->seed, why) : std::nullopt;
      const auto sim_to_real = on_sim ? weka_score(cls, o->sim, o->real, 0, o->seed, why) : std::nullopt;
      if (!sim_to_real) throw std::runtime_error(name + ": " + why);
      report["classifiers"][name] = {
          {"real", {{"percent_correct", on_real->correct_percent}, {"misclassified", on_real->misclassified}}},
          {"sim", {{"percent_correct", on_sim->correct_percent}, {"misclassified", on_sim->misclassified}}},
          {"sim_to_real",
           {{"percent_correct", sim_to_real->correct_percent}, {"misclassified", sim_to_real->misclassified}}}};
      md << "| " << name << " | " << on_real->correct_percent << " | " << on_real->misclassified << " | "
         << on_sim->correct_percent << " | " << on_sim->misclassified << " | " << sim_to_real->correct_percent << " | "
         << sim_to_real->misclassified << " |\n";
    }
    StagedFolder folder(o->out);
    write_text_atomic(folder.path("report.md"), md.str());
    write_text_atomic(folder.path("report.json"), report.dump(2) + "\n");
    folder.commit();
    std::printf("%s", md.str().c_str());
    return 0;
  };
}

}  // namespace portalsim::cli
