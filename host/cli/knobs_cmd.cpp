// portalsim knobs: the model's and the tiers' knobs as a Markdown table (docs/reference/knobs.md).
#include <cstdio>

#include "cli/commands.h"
#include "plan/knobs.h"

namespace portalsim::cli {

std::function<int()> add_knobs(CLI::App& app) {
  app.add_subcommand("knobs", "list every model and fidelity knob: flag, spec key, values, default");
  return [] {
    std::fputs(knob_table_markdown().c_str(), stdout);
    return 0;
  };
}

}  // namespace portalsim::cli
