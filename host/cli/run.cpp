#include <cstdio>
#include <map>

#include "cli/commands.h"
#include "scene/error.h"

namespace portalsim::cli {

int run(int argc, char** argv) {
  CLI::App app{"portalsim: simulated MMW, IR and metal detector outputs for security portal scenarios"};
  app.set_version_flag("--version", std::string("portalsim ") + PORTALSIM_VERSION);
  app.require_subcommand(1);
  std::map<std::string, std::function<int()>> commands;
  commands["simulate"] = add_simulate(app);
  commands["catalogue"] = add_catalogue(app);
  commands["generate"] = add_generate(app);
  commands["features"] = add_features(app);
  commands["tradeoff"] = add_tradeoff(app);
  commands["validate"] = add_validate(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (const auto& [name, fn] : commands)
      if (app.got_subcommand(name)) return fn();
  } catch (const InputError& e) {
    std::fprintf(stderr, "portalsim: error: %s\n", e.what());
    return 2;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "portalsim: error: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "portalsim: error: %s\n", e.what());
    return 1;
  }
  return 1;
}

}  // namespace portalsim::cli
