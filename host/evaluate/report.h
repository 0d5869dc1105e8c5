// The report of one evaluation: report.json (every number), report.md (the same as tables),
// scores.csv (every row's out-of-fold scores, from which all of it can be recomputed) and
// roc.csv (each curve's points, for the plots). Text only: the caller writes the files.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "evaluate/evaluation.h"

namespace portalsim::evaluate {

// `about`: what the caller knows of the data (source, rule, regions' places...), kept as
// report.json's "data".
nlohmann::json report_json(const Dataset& d, const Evaluation& e, const Options& o, const nlohmann::json& about);
std::string report_markdown(const nlohmann::json& report);
std::string scores_csv(const Dataset& d, const Evaluation& e);
std::string roc_csv(const Dataset& d, const Evaluation& e);

// Shortest text that reads back as the same double.
std::string number_text(double v);

}  // namespace portalsim::evaluate
