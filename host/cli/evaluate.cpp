// portalsim evaluate: what would this portal detect? ROC curves, AUC and Pd at stated Pfa,
// per sensor and fused, per region, from a generate folder, from a spec generated first, or
// over a sweep of settings (cli/evaluate_sweep.cpp); or the metal detector's sensitivity map
// (--metal-map, cli/evaluate_metal_map.cpp). The numbers are evaluate/'s.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "assets/image_io.h"
#include "base/embedded.h"
#include "base/error.h"
#include "base/parallel.h"
#include "cli/commands.h"
#include "cli/evaluate_data.h"
#include "cli/evaluate_metal_map.h"
#include "cli/evaluate_run.h"
#include "cli/evaluate_sweep.h"
#include "cli/python_requests.h"
#include "cli/spec_flags.h"
#include "cli/validate_tables.h"
#include "evaluate/report.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "schedule/pipeline.h"
#include "sink/staging.h"

namespace portalsim {
namespace cli {

namespace fs = std::filesystem;

namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct EvaluateOptions {
  SpecFlags flags;  // --spec, the data set's flags and knobs, --catalogue, --seed, --timing
  std::string dir, out, sweep, samples, part, pfa = "0.01,0.05,0.1", classifier = "trees", eval_seed = "1";
  int folds = 5, bootstrap = 1000;
  unsigned threads = 0;
  bool plot = true;
};

// The evaluation's settings from the flags, checked before anything runs.
EvaluateSettings settings_from(const EvaluateOptions& o) {
  EvaluateSettings s;
  evaluate::Options& e = s.options;
  e.classifier = evaluate::parse_classifier(o.classifier, "--classifier");
  if (o.folds < 2 || o.folds > 100)
    throw InputError("--folds: " + std::to_string(o.folds) + " is not between 2 and 100");
  e.folds = o.folds;
  if (o.bootstrap < 10 || o.bootstrap > 100000)
    throw InputError("--bootstrap: " + std::to_string(o.bootstrap) + " is not between 10 and 100000");
  e.bootstrap = o.bootstrap;
  e.seed = io::parse_u64(o.eval_seed, "--eval-seed");
  e.pfa.clear();
  for (const std::string& item : split_commas(o.pfa)) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(v > 0 && v < 1))
      throw InputError("--pfa: \"" + item + "\" is not a false-alarm rate between 0 and 1 (exclusive)");
    e.pfa.push_back(v);
  }
  e.threads = o.threads ? o.threads : default_threads();
  s.plot = o.plot;
  s.timing = o.flags.common.timing;
  return s;
}

void check_new_or_empty(const std::string& out) {
  if (out.empty()) throw InputError("--out: empty folder name");
  std::error_code ec;
  if (fs::exists(out, ec) && (!fs::is_directory(out, ec) || !fs::is_empty(out, ec)))
    throw OutputError(out + ": is not an empty folder; choose a new one");
}

int run_evaluate(EvaluateOptions& o) {
  // Exactly one mode: a folder, a spec generated first, or a sweep.
  std::vector<std::string> modes;
  if (!o.dir.empty()) modes.push_back("DIR");
  const bool sweep = !o.sweep.empty() || !o.samples.empty();
  if (sweep) modes.push_back("--sweep");
  if (!o.flags.spec_file.empty() && !sweep) modes.push_back("--spec");
  if (modes.size() != 1)  // "dir:" names the positional argument: a usage error
    throw InputError(
        std::string(modes.empty() ? "dir: nothing to evaluate" : "dir: more than one of DIR, --spec, --sweep") +
        ": give a generate folder DIR, --spec FILE (generated first), --sweep/--samples, or --metal-map OBJECT");
  if (!o.dir.empty()) {  // a folder is evaluated as it was made: flags that make a data set are refused
    const CLI::App& app = *o.flags.app;
    for (const char* flag : {"--count", "--rule", "--pool", "--objects", "--subjects", "--bodies", "--body-count",
                             "--body-seed", "--balance", "--tier"})
      if (app.get_option(flag)->count() > 0)
        throw InputError(std::string(flag) + ": makes a data set; it goes with --spec or --sweep, not with DIR");
    for (const auto& [key, text] : given_knobs(app, o.flags.knobs))
      throw InputError(find_knob(key)->flag() +
                       ": a knob makes a data set; it goes with --spec or --sweep, not with DIR");
  }
  const EvaluateSettings settings = settings_from(o);
  if (sweep) return run_sweep(o.flags, o.sweep, o.samples, o.part, o.out, settings);
  check_new_or_empty(o.out);
  Session s;
  EvaluateTiming timing;
  std::string data = o.dir;
  // A folder's subjects are those it was made with: its random bodies drawn again.
  RunSpec spec = o.flags.spec_file.empty() ? bodies_of_folder(o.dir) : features_spec(build_spec(o.flags));
  open_catalogue(s, o.flags.common, &spec);
  if (!o.flags.spec_file.empty()) check_generate(spec, s.catalogue);
  StagedFolder folder(o.out);
  if (!o.flags.spec_file.empty()) {
    open_backend(s, o.flags.common);
    data = folder.path("data");
    timing.generation = generate_data(spec, s, data, settings.options.threads);
  }
  // The report names the data where it will be, not where it is staged.
  const std::string source = o.dir.empty() ? (fs::path(o.out) / "data").string() : o.dir;
  const nlohmann::json report = evaluate_folder(data, s, settings, folder.dir(), timing, source);
  for (const char* name : {"report.md", "report.json", "scores.csv", "roc.csv"}) folder.path(name);
  if (settings.plot)
    for (const auto& p : report["plots"]) folder.path(p.get<std::string>());
  folder.commit();
  std::printf("%s", evaluate::report_markdown(report).c_str());
  if (settings.timing) std::printf("%s\n", timing.line().c_str());
  return 0;
}

}  // namespace

void EvaluateTiming::add(const EvaluateTiming& t) {
  generation += t.generation;
  reading += t.reading;
  training += t.training;
  bootstrap += t.bootstrap;
  plots += t.plots;
}

std::string EvaluateTiming::line() const {
  char b[256];
  std::snprintf(b, sizeof b,
                "timing: generation %.2f s, reading the table %.2f s, training %.2f s, bootstrap %.2f s, plots %.2f s",
                generation, reading, training, bootstrap, plots);
  return b;
}

RunSpec features_spec(RunSpec spec) {
  spec.what = "features";
  spec.formats = {"csv"};
  spec.annotations = false;
  spec.compress = false;
  spec.validate();
  return spec;
}

double generate_data(const RunSpec& spec, Session& s, const std::string& dir, unsigned threads) {
  const auto t0 = std::chrono::steady_clock::now();
  PipelineOptions popt;
  popt.threads = threads;
  run_pipeline(spec, s.catalogue, s.assets, *s.backend, dir, popt);
  return since(t0);
}

nlohmann::json evaluate_folder(const std::string& data, const Session& s, const EvaluateSettings& settings,
                               const std::string& report_dir, EvaluateTiming& timing, const std::string& source) {
  auto t0 = std::chrono::steady_clock::now();
  EvaluateData in = read_evaluate_data(data, s.catalogue);
  if (!source.empty()) in.about["source"] = source;
  timing.reading += since(t0);
  const evaluate::Evaluation e = evaluate::run_evaluation(in.data, settings.options);
  timing.training += e.timing.training;
  timing.bootstrap += e.timing.bootstrap;
  nlohmann::json report = evaluate::report_json(in.data, e, settings.options, in.about);
  const fs::path dir(report_dir);
  if (settings.plot) {
    report["plots"] = {"roc.png"};
    if (!e.regions.empty()) report["plots"].push_back("regions.png");
  }
  write_text_atomic((dir / "report.json").string(), report.dump(2) + "\n");
  write_text_atomic((dir / "report.md").string(), evaluate::report_markdown(report));
  write_text_atomic((dir / "scores.csv").string(), evaluate::scores_csv(in.data, e));
  write_text_atomic((dir / "roc.csv").string(), evaluate::roc_csv(in.data, e));
  if (settings.plot) {
    t0 = std::chrono::steady_clock::now();
    // The body the regions are drawn on: subject 1's MMW views, removed after.
    std::vector<std::string> bodies;
    for (size_t k = 0; k < s.catalogue.sensors.size(); ++k)
      if (s.catalogue.sensors[k].pooled && !s.assets.bases.empty()) {
        bodies.push_back((dir / (".body_" + s.catalogue.sensors[k].name + ".png")).string());
        write_image(bodies.back(), s.assets.bases[0][k]);
      }
    run_plot_script(embedded::plot_evaluate, report_dir, {report_dir}, "roc.png");
    std::error_code ec;
    for (const std::string& b : bodies) fs::remove(b, ec);
    timing.plots += since(t0);
  }
  return report;
}

std::function<int()> add_evaluate(CLI::App& app) {
  auto o = std::make_shared<EvaluateOptions>();
  CLI::App* sub = app.add_subcommand("evaluate", "ROC, AUC and Pd at Pfa per sensor and fused, per region; sweeps");
  add_spec_flags(sub, &o->flags, false);
  sub->add_option("dir", o->dir, "a folder made by portalsim generate (features.csv, features.arff or data.h5)");
  sub->add_option("--out", o->out, "report folder (must be new or empty; a sweep's resumes)")->required();
  sub->add_option("--sweep", o->sweep,
                  "grid of knob values, e.g. \"netd=1,2,3 mmw_raw=16x16,28x28\"; with --samples: "
                  "ranges, e.g. \"netd=1..4 frames=1..10\"");
  sub->add_option("--samples", o->samples, "N settings drawn by Latin hypercube over --sweep's ranges");
  sub->add_option("--part", o->part, "i/k: run only the sweep's points i, i+k, ... (a Slurm array task's share)");
  sub->add_option("--classifier", o->classifier, "trees (gradient-boosted, default) or logistic");
  sub->add_option("--folds", o->folds, "cross-validation folds (default 5)");
  sub->add_option("--bootstrap", o->bootstrap, "bootstrap draws for the 95% intervals (default 1000)");
  sub->add_option("--pfa", o->pfa, "target false-alarm rates, comma-separated (default 0.01,0.05,0.1)");
  sub->add_option("--eval-seed", o->eval_seed, "seed of the folds and the bootstrap (default 1)");
  sub->add_option("--threads", o->threads, "threads for generating and training (default: all cores)");
  sub->add_flag("!--no-plot", o->plot, "skip the plots (needs no python3 with matplotlib)");
  // The metal detector's sensitivity map, a mode of its own (host/cli/evaluate_metal_map.cpp).
  auto metal_map = add_metal_map(*sub);
  return [o, metal_map, sub] {
    if (sub->get_option("--metal-map")->count() > 0 &&
        (!o->dir.empty() || !o->sweep.empty() || !o->samples.empty() || !o->flags.spec_file.empty()))
      throw InputError("--metal-map: maps the metal detector alone; not with DIR, --spec, --sweep or --samples");
    if (const std::optional<int> rc = metal_map()) return *rc;
    return run_evaluate(*o);
  };
}

}  // namespace cli
}  // namespace portalsim
