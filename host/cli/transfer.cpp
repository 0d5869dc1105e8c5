// `portalsim transfer`: does a detector trained on one data set hold on others (issue 34:
// held-out bodies, another camera)? WEKA's classifiers (default settings) are trained once
// per test set on the training set and scored on that test set; each accuracy gets Wilson's
// 95% interval, and each set's loss against the first test set (the in-domain one) an
// interval for the difference of two independent proportions (Newcombe's hybrid score).
// A set is a run spec (.toml, generated here under OUT/sets/NAME/), a feature table (ARFF,
// CSV, data.h5) or a folder of scenario folders.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "base/embedded.h"
#include "base/error.h"
#include "base/spoken_list.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/learning_sets.h"
#include "cli/validate_stats.h"
#include "cli/weka.h"
#include "io/input_file.h"
#include "schedule/pipeline.h"
#include "schedule/run_spec.h"
#include "sink/staging.h"

namespace portalsim {
namespace cli {

namespace {

namespace fs = std::filesystem;

// The classifiers by their flag name (WEKA's, tools/Weka.java, or the CNN) and the report's name.
struct Classifier {
  const char* key;
  bool weka;
  const char* name;
};
constexpr Classifier kClassifiers[] = {
    {"j48", true, "J48"}, {"svm", true, "SMO"}, {"mlp", true, "MLP"}, {"cnn", false, "CNN"}};

struct Options {
  std::string train, out, classifiers = "j48,svm", catalogue, cnn_inputs;  // cnn_inputs: "" is kDefaultCnnInputs
  std::vector<std::string> tests;
  int block = 10, cnn_steps = 300;
  double max_loss = 3.0;
};

// One data set: its name in the report, where it comes from, and its spec when it is one.
struct Set {
  std::string name, source;
  std::unique_ptr<RunSpec> spec;
  Table table;
};

bool is_spec(const std::string& path) { return fs::path(path).extension() == ".toml"; }

// A name of letters, digits, '-', '_' and '.', not starting with '.': a folder's name too.
bool good_name(const std::string& n) {
  if (n.empty() || n.size() > 64 || n[0] == '.') return false;
  return std::all_of(n.begin(), n.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
           c == '.';
  });
}

// The sensors the CNN may see, by --cnn-inputs' names (tools/transfer_cnn.py reads them).
constexpr const char* kCnnInputs[] = {"mmw", "ir", "metal"};
constexpr const char* kDefaultCnnInputs = "mmw,ir,metal";

// The data.h5 datasets each camera kind's branch reads (by Camera), from the catalogue's
// views: each of its views (a front-and-back portal's four MMW views), a palette view's indices.
using CnnDatasets = std::vector<std::vector<std::string>>;
const std::vector<std::string> kMetalDatasets{"metal"};
CnnDatasets cnn_datasets(const Catalogue& cat) {
  CnnDatasets d(camera_kinds().size());
  for (const Sensor& s : cat.sensors)
    d[static_cast<size_t>(s.camera)].push_back(s.palette ? s.name + "_index" : s.name);
  return d;
}

std::string joined(const std::vector<std::string>& v, const char* sep) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

std::string cnn_input_words(const std::string& sensor, const CnnDatasets& d) {
  const CameraKind* kind = camera_kind_named(sensor);
  if (!kind) return "the metal detector's zones";
  const std::vector<std::string>& views = d[static_cast<size_t>(kind->camera)];
  return std::string("the ") + kind->label + " " + kind->nouns[views.size() == 1 ? 0 : 1] + " (" + joined(views, ", ") +
         ")";
}

// --cnn-inputs' value, checked: distinct names of kCnnInputs, in the order given.
std::vector<std::string> cnn_inputs(const std::string& text) {
  std::vector<std::string> out;
  for (const std::string& s : split_commas(text)) {
    if (std::find(std::begin(kCnnInputs), std::end(kCnnInputs), s) == std::end(kCnnInputs))
      throw InputError("--cnn-inputs: unknown sensor '" + s + "' (mmw, ir or metal)");
    if (std::find(out.begin(), out.end(), s) != out.end()) throw InputError("--cnn-inputs: '" + s + "' is given twice");
    out.push_back(s);
  }
  if (out.empty()) throw InputError("--cnn-inputs: none given (mmw, ir or metal)");
  return out;
}

// What the CNN is given: --cnn-inputs' sensors, the datasets each reads (from the catalogue
// the sets are made with, and a data.h5 set was made with), the script's arguments for
// them, and the report's words and list.
struct Cnn {
  std::vector<std::string> sensors, words, args;
  nlohmann::json datasets = nlohmann::json::array();  // in the order the CNN reads them
};
Cnn cnn_of(const Options& o) {
  Cnn c;
  c.sensors = cnn_inputs(o.cnn_inputs.empty() ? kDefaultCnnInputs : o.cnn_inputs);
  const CnnDatasets d = cnn_datasets(o.catalogue.empty() ? default_catalogue() : load_catalogue(o.catalogue));
  for (const std::string& sensor : c.sensors) {
    const CameraKind* kind = camera_kind_named(sensor);
    const std::vector<std::string>& read = kind ? d[static_cast<size_t>(kind->camera)] : kMetalDatasets;
    if (read.empty())
      throw InputError("--cnn-inputs: " + sensor + ", but the catalogue (" +
                       (o.catalogue.empty() ? std::string("built-in") : o.catalogue) + ") has no " + kind->label +
                       " view");
    c.words.push_back(cnn_input_words(sensor, d));
    for (const std::string& ds : read) c.datasets.push_back(ds);
  }
  c.args = {"--inputs", joined(c.sensors, ",")};
  for (const CameraKind* kind : camera_kinds())  // --mmw-views, --ir-views
    c.args.insert(c.args.end(),
                  {std::string("--") + kind->name + "-views", joined(d[static_cast<size_t>(kind->camera)], ",")});
  return c;
}

// `images`: the CNN is among the classifiers, so a spec's set is made with its images and
// zones (data.h5) and any other set must be a data.h5 that holds them.
Set make_set(const std::string& name, const std::string& source, const std::string& flag, bool images) {
  Set s{.name = name, .source = source, .spec = nullptr, .table = {}};
  if (source.empty()) throw InputError(flag + ": " + name + ": no data set given");
  if (is_spec(source)) {
    // Read now: a bad spec stops the command before anything is made.
    s.spec = std::make_unique<RunSpec>();
    read_spec_file(source, *s.spec);
    s.spec->what = images ? "both" : "features";
    s.spec->formats = images ? std::vector<std::string>{"arff", "h5"} : std::vector<std::string>{"arff"};
    s.spec->validate();
  } else {
    std::error_code ec;
    if (!fs::exists(source, ec)) throw InputError(flag + ": " + source + ": no such file or folder");
    if (images && fs::path(source).extension() != ".h5")
      throw InputError(flag + ": " + source +
                       ": the CNN needs the sensors' images and zones: give a run spec (.toml) or a "
                       "data.h5 with images");
  }
  return s;
}

// The set's data.h5 for the CNN: the one made here for a spec, else the set itself.
std::string images_of(const Set& s, const std::string& made) {
  return s.spec ? (fs::path(made) / s.name / "data.h5").string() : s.source;
}

std::string percent(double fraction) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", 100 * fraction);
  return b;
}

// --classifiers' value, checked: known names, each once, in the order given.
std::vector<const Classifier*> chosen_classifiers(const std::string& text) {
  std::vector<const Classifier*> chosen;
  for (const std::string& c : split_commas(text)) {
    const auto it = std::find_if(std::begin(kClassifiers), std::end(kClassifiers),
                                 [&](const Classifier& k) { return lower(c) == k.key; });
    if (it == std::end(kClassifiers))
      throw InputError("--classifiers: unknown classifier '" + c + "' (j48, svm, mlp or cnn)");
    if (std::find(chosen.begin(), chosen.end(), &*it) == chosen.end()) chosen.push_back(&*it);
  }
  if (chosen.empty()) throw InputError("--classifiers: none given (j48, svm, mlp or cnn)");
  return chosen;
}

// --train and each --test NAME=SET, checked, the training set first.
std::vector<Set> sets_of(const Options& o, bool images) {
  std::vector<Set> sets;
  sets.push_back(make_set("train", o.train, "--train", images));
  std::set<std::string> names{"train"};
  for (const std::string& t : o.tests) {
    const size_t eq = t.find('=');
    if (eq == std::string::npos) throw InputError("--test: '" + t + "' is not NAME=SET");
    const std::string name = t.substr(0, eq);
    if (!good_name(name))
      throw InputError("--test: '" + name + "' is not a name (letters, digits, '-', '_', '.'; at most 64)");
    if (!names.insert(name).second) throw InputError("--test: the name '" + name + "' is given twice");
    sets.push_back(make_set(name, t.substr(eq + 1), "--test", images));
  }
  if (sets.size() < 2) throw InputError("--test: at least one test set is needed (NAME=SET)");
  return sets;
}

// The specs' sets, made under `made` (OUT/sets/) and read back as feature tables.
void make_spec_sets(const Options& o, std::vector<Set>& sets, const std::string& made) {
  fs::create_directories(made);
  CommonOptions co;
  co.catalogue = o.catalogue;
  Session session;
  open_catalogue(session, co);
  for (const Set& s : sets)
    if (s.spec) validate(s.spec->settings(), session.catalogue);
  open_backend(session, co);
  PipelineOptions popt;
  popt.progress = false;
  // Sets of drawn bodies draw theirs from their body seed: one session per (body seed,
  // count; 0 for a body per scenario), which the sets that share them share (the training
  // bodies tested again).
  std::map<std::pair<uint64_t, int>, Session> drawn;
  for (Set& s : sets) {
    if (!s.spec) continue;
    const std::string dir = (fs::path(made) / s.name).string();
    Session* use = &session;
    if (s.spec->drawn_bodies()) {
      const auto [it, fresh] = drawn.try_emplace({s.spec->bodies_seed(), s.spec->random_bodies()});
      if (fresh) {
        open_catalogue(it->second, co, s.spec.get());
        open_backend(it->second, co);
      }
      use = &it->second;
    }
    run_pipeline(*s.spec, use->catalogue, use->assets, *use->backend, dir, popt);
    std::fprintf(stderr, "transfer: %s: %llu scenarios from %s\n", s.name.c_str(),
                 static_cast<unsigned long long>(s.spec->count), s.source.c_str());
    s.table = read_arff((fs::path(dir) / "features.arff").string());
    s.table.path = (fs::path(o.out) / "sets" / s.name / "features.arff").string();
  }
}

// The other sets' tables, read; every set checked against the training set's attributes;
// each written as ARFF under `scratch` with the classes of all, for WEKA. Their paths.
std::vector<std::string> arff_tables(const Options& o, std::vector<Set>& sets, const std::string& scratch) {
  for (Set& s : sets)
    if (!s.spec) s.table = load_table(s.source, scratch, s.name, o.block, o.catalogue);
  std::set<std::string> classes;
  for (const Set& s : sets) {
    check_same_attributes(sets[0].table, s.table);
    if (s.table.rows.empty()) throw InputError(s.table.path + ": no instances");
    classes.insert(s.table.classes.begin(), s.table.classes.end());
  }
  if (sets[0].table.classes.size() < 2) throw InputError(sets[0].table.path + ": the training set has a single class");
  std::vector<std::string> arff;
  for (const Set& s : sets) {
    arff.push_back((fs::path(scratch) / (s.name + ".arff")).string());
    write_arff(s.table, classes, arff.back());
  }
  return arff;
}

// The CNN trained on the first set's images and zones, scored on each other's: correct per
// set (0 for the training set).
std::vector<long> cnn_scores(const Options& o, const Cnn& cnn, const std::vector<Set>& sets, const std::string& made,
                             const std::string& scratch) {
  const std::string scores = (fs::path(scratch) / "cnn.json").string();
  std::vector<std::string> args{scores, "--steps", std::to_string(o.cnn_steps)};
  args.insert(args.end(), cnn.args.begin(), cnn.args.end());
  for (const Set& s : sets) args.push_back(images_of(s, made));
  if (!run_python_script(embedded::transfer_cnn, scratch, args))
    throw EnvironmentError(
        "transfer: the CNN failed (its message is above; it needs Debian's python3-torch, python3-h5py and "
        "python3-numpy)");
  const nlohmann::json j = nlohmann::json::parse(io::read_text_file(scores, "CNN scores", io::Bom::refuse));
  std::vector<long> correct(sets.size(), 0);
  for (size_t k = 1; k < sets.size(); ++k) {
    correct[k] = j.at("correct").at(k - 1).get<long>();
    if (j.at("n").at(k - 1).get<size_t>() != sets[k].table.rows.size())
      throw InputError(images_of(sets[k], made) + ": its images and its feature table differ in count");
    std::fprintf(stderr, "transfer: CNN on %s: %s%%\n", sets[k].name.c_str(),
                 percent(double(correct[k]) / static_cast<double>(sets[k].table.rows.size())).c_str());
  }
  return correct;
}

// A WEKA classifier trained once on the first ARFF, scored on each other's: correct per set.
std::vector<long> weka_correct(const Classifier& c, const std::vector<std::string>& arff,
                               const std::vector<Set>& sets) {
  std::string why;
  const auto s = weka_scores(
      {{.classifier = c.key, .train = arff[0], .tests = {arff.begin() + 1, arff.end()}, .folds = 0, .seed = 0}}, why);
  if (!s) throw EnvironmentError(std::string("WEKA ") + c.name + ": " + why);
  std::vector<long> correct(sets.size(), 0);
  for (size_t k = 1; k < sets.size(); ++k) {
    correct[k] = (*s)[0][k - 1].correct;
    std::fprintf(stderr, "transfer: %s on %s: %s%%\n", c.name, sets[k].name.c_str(),
                 percent(double(correct[k]) / static_cast<double>(sets[k].table.rows.size())).c_str());
  }
  return correct;
}

// report.md and report.json's scores: per test set and classifier, the accuracy with its
// interval and, past the reference (the first test set), the loss against it; then whether
// each classifier holds.
void add_scores(const Options& o, const std::vector<const Classifier*>& chosen, const std::vector<Set>& sets,
                const std::vector<std::vector<long>>& correct, std::ostringstream& md, nlohmann::json& report) {
  md << "\n\n| test set | instances |";
  for (const Classifier* c : chosen) md << " " << c->name << " | " << c->name << " loss |";
  md << "\n| --- | --- |";
  for (size_t c = 0; c < chosen.size(); ++c) md << " --- | --- |";
  md << "\n";
  // Each set's loss against the reference, in points (the second set on).
  std::vector<std::vector<double>> loss(chosen.size(), std::vector<double>(sets.size(), 0));
  for (size_t k = 1; k < sets.size(); ++k) {
    const long n = static_cast<long>(sets[k].table.rows.size()), n0 = static_cast<long>(sets[1].table.rows.size());
    nlohmann::json row = {{"name", sets[k].name}, {"source", sets[k].source}, {"instances", n}};
    md << "| " << sets[k].name << " | " << n << " |";
    for (size_t c = 0; c < chosen.size(); ++c) {
      const Interval a = wilson(correct[c][k], n);
      nlohmann::json score = {{"correct", correct[c][k]},
                              {"percent_correct", 100.0 * correct[c][k] / n},
                              {"interval", {100 * a.lo, 100 * a.hi}}};
      md << " " << percent(double(correct[c][k]) / n) << " [" << percent(a.lo) << ", " << percent(a.hi) << "] |";
      if (k == 1) {
        md << " |";
      } else {
        const Interval d = newcombe_difference(correct[c][1], n0, correct[c][k], n);
        loss[c][k] = 100 * (double(correct[c][1]) / n0 - double(correct[c][k]) / n);
        score["loss_points"] = {{"value", loss[c][k]}, {"interval", {100 * d.lo, 100 * d.hi}}};
        md << " " << percent(loss[c][k] / 100) << " [" << percent(d.lo) << ", " << percent(d.hi) << "] |";
      }
      row["scores"][chosen[c]->name] = score;
    }
    md << "\n";
    report["tests"].push_back(row);
  }
  // The verdict: whether each classifier loses at most max_loss points on every other set.
  md << "\nHolds (loses at most " << o.max_loss << " points against `" << sets[1].name << "` on every other set):";
  for (size_t c = 0; c < chosen.size(); ++c) {
    std::string worst;
    double worst_loss = -1e9;
    for (size_t k = 2; k < sets.size(); ++k)
      if (loss[c][k] > worst_loss) worst_loss = loss[c][k], worst = sets[k].name;
    const bool holds = sets.size() < 3 || worst_loss <= o.max_loss;
    report["holds"][chosen[c]->name] = holds;
    md << " " << chosen[c]->name << ": " << (holds ? "yes" : "no");
    if (sets.size() >= 3) md << " (largest loss " << percent(worst_loss / 100) << " points, `" << worst << "`)";
    md << (c + 1 < chosen.size() ? ";" : ".\n");
  }
}

int run_transfer(const Options& o) {
  // Every argument is checked before anything is written or run.
  const std::vector<const Classifier*> chosen = chosen_classifiers(o.classifiers);
  const bool cnn = std::any_of(chosen.begin(), chosen.end(), [](const Classifier* c) { return !c->weka; });
  if (!o.cnn_inputs.empty() && !cnn) throw InputError("--cnn-inputs: only applies with --classifiers cnn");
  const Cnn cnn_in = cnn ? cnn_of(o) : Cnn{};
  const bool weka = std::any_of(chosen.begin(), chosen.end(), [](const Classifier* c) { return c->weka; });
  std::vector<Set> sets = sets_of(o, cnn);
  if (const auto missing = weka_missing(); weka && missing) throw EnvironmentError("transfer: " + *missing);

  const WorkDir scratch;
  StagedFolder folder(o.out);
  // The specs' sets, made here and kept under sets/.
  const bool any_spec = std::any_of(sets.begin(), sets.end(), [](const Set& s) { return s.spec != nullptr; });
  const std::string made = any_spec ? folder.path("sets") : std::string();
  if (any_spec) make_spec_sets(o, sets, made);
  const std::vector<std::string> arff = arff_tables(o, sets, scratch.path);

  // Scores: per classifier, per test set, correct of n.
  std::vector<std::vector<long>> correct;
  for (const Classifier* c : chosen)
    correct.push_back(c->weka ? weka_correct(*c, arff, sets) : cnn_scores(o, cnn_in, sets, made, scratch.path));

  nlohmann::json report = {{"train", {{"source", sets[0].source}, {"instances", sets[0].table.rows.size()}}},
                           {"attributes", sets[0].table.names.size() - 1},
                           {"reference", sets[1].name},
                           {"max_loss_points", o.max_loss},
                           {"interval", "95%: Wilson (accuracy), Newcombe's hybrid score (loss)"}};
  if (cnn) {
    report["cnn_inputs"] = cnn_in.sensors;
    report["cnn_datasets"] = cnn_in.datasets;
  }
  std::ostringstream md;
  md << "# portalsim transfer\n\nTrained on `" << sets[0].source << "` (" << sets[0].table.rows.size() << " instances, "
     << sets[0].table.names.size() - 1
     << " attributes), tested on each set below. Accuracy in percent with Wilson's 95% interval; loss: `"
     << sets[1].name
     << "`'s accuracy minus the set's, in points, with the 95% interval of a difference of two independent "
        "proportions (Newcombe's hybrid score).";
  if (cnn) md << " The CNN sees " << spoken_list(cnn_in.words) << ".";
  add_scores(o, chosen, sets, correct, md, report);
  write_text_atomic(folder.path("report.md"), md.str());
  write_text_atomic(folder.path("report.json"), report.dump(2) + "\n");
  folder.commit();
  std::printf("%s", md.str().c_str());
  return 0;
}

}  // namespace

std::function<int()> add_transfer(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "transfer", "Train on one data set, test on others: accuracy and loss against the first, with intervals");
  cmd->add_option("--train", o->train,
                  "Training set: a run spec (.toml, generated under OUT/sets/train), a feature table (ARFF, CSV, "
                  "data.h5) or a folder of scenario folders")
      ->required();
  cmd->add_option("--test", o->tests,
                  "NAME=SET, repeated: the sets to test on, the first the in-domain one the others' loss is "
                  "measured against")
      ->required();
  cmd->add_option("--out", o->out, "Folder for report.md, report.json and the specs' sets")->required();
  cmd->add_option("--classifiers", o->classifiers,
                  "Comma-separated: j48, svm, mlp (WEKA, on the features) and cnn (a small CNN on the sensors' "
                  "images and zones, --cnn-inputs; python3-torch) (default j48,svm)");
  cmd->add_option(
      "--cnn-inputs", o->cnn_inputs,
      "Comma-separated sensors the CNN sees: mmw (the catalogue's MMW views), ir (the IR image), metal (the "
      "metal detector's zones) (default mmw,ir,metal)");
  cmd->add_option("--cnn-steps", o->cnn_steps, "Training steps of the CNN, batches of 32 (default 300)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--catalogue", o->catalogue, "Catalogue TOML for the specs and folders (default: built-in)");
  cmd->add_option("--block", o->block, "Block side for folders turned into tables (default 10)")
      ->check(CLI::Range(1, 65536));
  cmd->add_option("--max-loss", o->max_loss, "Points a classifier may lose and still hold (default 3)")
      ->check(CLI::Range(0.0, 100.0));
  return [o]() { return run_transfer(*o); };
}

}  // namespace cli
}  // namespace portalsim
