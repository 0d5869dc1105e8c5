// portalsim evaluate --sweep / --samples: a data set and its evaluation per setting of the
// knobs, each point kept as it finishes (a rerun resumes), then a table and plots of Pd at
// Pfa against each knob.
#pragma once
#include <string>

#include "cli/evaluate_run.h"
#include "cli/spec_flags.h"

namespace portalsim::cli {

// `part` "i/k" (or empty): run only the points whose index is i modulo k (a Slurm array
// task's share); the table is written by the run that finds every point done.
int run_sweep(SpecFlags& flags, const std::string& sweep, const std::string& samples, const std::string& part,
              const std::string& out, const EvaluateSettings& settings);

}  // namespace portalsim::cli
