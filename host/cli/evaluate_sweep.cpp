#include "cli/evaluate_sweep.h"

#include "base/error.h"

namespace portalsim::cli {

int run_sweep(SpecFlags&, const std::string&, const std::string&, const std::string&, const EvaluateSettings&) {
  throw InputError("--sweep: not yet");
}

}  // namespace portalsim::cli
