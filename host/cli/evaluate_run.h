// What `portalsim evaluate`'s modes share (cli/evaluate.cpp, cli/evaluate_sweep.cpp): the
// evaluation's settings from the command line, making a data set by generate's code path,
// and one evaluation of a generate folder written as a report.
#pragma once
#include <string>

#include "cli/common.h"
#include "evaluate/evaluation.h"
#include "schedule/run_spec.h"

namespace portalsim::cli {

struct EvaluateSettings {
  evaluate::Options options;
  bool plot = true;
  bool timing = false;
};

// Where the time of one evaluation went (seconds); --timing prints it.
struct EvaluateTiming {
  double generation = 0, reading = 0, training = 0, bootstrap = 0, plots = 0;
  void add(const EvaluateTiming& t);
  std::string line() const;
};

// The spec as evaluate generates it: features only, as features.csv, no annotations.
RunSpec features_spec(RunSpec spec);

// Generates `spec` into `dir` (new or empty) by generate's pipeline on the session's
// backend; returns the seconds it took.
double generate_data(const RunSpec& spec, Session& s, const std::string& dir, unsigned threads);

// Evaluates the generate folder `data` and writes report.md, report.json, scores.csv,
// roc.csv and (with plots) roc.png and regions.png into `report_dir`, an existing folder
// (a staging folder: the caller renames it into place). `source` names the data in the
// report (default: the folder). Returns report.json.
nlohmann::json evaluate_folder(const std::string& data, const Session& s, const EvaluateSettings& settings,
                               const std::string& report_dir, EvaluateTiming& timing, const std::string& source = "");

}  // namespace portalsim::cli
