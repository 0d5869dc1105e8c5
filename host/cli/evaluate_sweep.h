// portalsim evaluate --sweep / --samples: a data set and its evaluation per setting of the
// knobs, each point kept as it finishes (a rerun resumes), then a table and plots of Pd at
// Pfa against each knob.
#pragma once
#include <string>

#include "cli/evaluate_run.h"
#include "cli/spec_flags.h"

namespace portalsim::cli {

int run_sweep(SpecFlags& flags, const std::string& sweep, const std::string& samples, const std::string& out,
              const EvaluateSettings& settings);

}  // namespace portalsim::cli
