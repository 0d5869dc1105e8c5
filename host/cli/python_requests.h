// What `portalsim generate ARGS` or `portalsim simulate ARGS` would do, without doing it:
// Python (python/) takes its keywords through here, so that they mean what the flags mean
// and fail with the same messages.
#pragma once
#include <string>
#include <vector>

#include "cli/common.h"
#include "schedule/run_spec.h"

namespace portalsim::cli {

struct GenerateRequest {
  RunSpec spec;  // the --spec file, then the flags given over it, checked as generate checks them
  CommonOptions common;
  unsigned threads = 0;  // 0 = all cores
};

// `args` as generate's flags ("--seed", "1", "--rotate=-30..30"); throws InputError with the
// command line's message (a spec file's errors name its file and line).
GenerateRequest parse_generate(const std::vector<std::string>& args);

// Checks `spec` against the catalogue as generate does before it writes anything (the
// generator's spec, then the model's settings); throws InputError.
void check_generate(const RunSpec& spec, const Catalogue& cat);

struct SimulateRequest {
  CommonOptions common;
  RunSpec bodies;  // the subjects: --bodies, --body-count, --body-seed (open_catalogue's spec)
  Scenario scene;
  Plan plan;  // the model and fidelity, as simulate runs them
};

// `args` as simulate's (objects, then flags); the scenario and plan are made when `cat` is
// given (the catalogue `common` and `bodies` name, opened by the caller). Throws as parse_generate.
SimulateRequest parse_simulate(const std::vector<std::string>& args, const Catalogue* cat);

}  // namespace portalsim::cli
