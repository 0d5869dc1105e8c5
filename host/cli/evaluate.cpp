// portalsim evaluate: in this build only its metal detector sensitivity maps
// (--metal-map, host/cli/evaluate_metal_map.cpp).
#include "base/error.h"
#include "cli/commands.h"
#include "cli/evaluate_metal_map.h"

namespace portalsim::cli {

std::function<int()> add_evaluate(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("evaluate", "walk-through metal detector sensitivity maps (--metal-map)");
  auto metal_map = add_metal_map(*sub);
  return [metal_map] {
    if (const std::optional<int> rc = metal_map()) return *rc;
    throw InputError("--metal-map: evaluate needs an object to map");
  };
}

}  // namespace portalsim::cli
