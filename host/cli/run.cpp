#include <cstdio>
#include <map>
#include <utility>

#include "base/error.h"
#include "cli/commands.h"
#include "io/input_file.h"

namespace portalsim::cli {

namespace {

// Exit codes (docs/reference/exit-codes.md): a bad flag or value 2, a bad input file 3, an
// output problem 4, a missing OpenCL environment 5, anything else 1. Errors in flag
// values name the flag first, errors in positional arguments their name.
constexpr int kUsage = 2, kBadInput = 3, kOutput = 4, kEnvironment = 5, kInternal = 1;

bool g_print_errors = true;

int fail(const char* what, int code) {
  if (g_print_errors) std::fprintf(stderr, "portalsim: error: %s\n", what);
  return code;
}

// Every value given on the command line passes the input layer's byte checks.
void check_values(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options())
    for (const std::string& v : o->results()) io::check_flag_value(v, o->get_name());
  for (const CLI::App* sub : app.get_subcommands()) check_values(*sub);
}

// Whether an error message starts by naming a command-line argument of `command`: a flag
// ("--pool: ...") or a positional argument ("objects: ..."). Such an error is a usage error;
// an error naming a file (and its line) is bad input.
bool names_an_argument(std::string_view message, const CLI::App* command) {
  if (message.starts_with("--")) return true;
  if (!command) return false;
  for (const CLI::Option* o : command->get_options())
    if (o->get_positional() && message.starts_with(o->get_name() + ":")) return true;
  return false;
}

// The built-in subcommands, in the order `portalsim --help` lists them.
constexpr std::pair<const char*, std::function<int()> (*)(CLI::App&)> kCommands[] = {
    {"simulate", add_simulate}, {"catalogue", add_catalogue}, {"generate", add_generate},   {"features", add_features},
    {"tradeoff", add_tradeoff}, {"serve", add_serve},         {"validate", add_validate},   {"transfer", add_transfer},
    {"knobs", add_knobs},       {"merge", add_merge},         {"calibrate", add_calibrate}, {"evaluate", add_evaluate}};

}  // namespace

void print_errors(bool on) { g_print_errors = on; }

int run(int argc, char** argv, const std::map<std::string, AddCommand>& more) {
  CLI::App app{"portalsim: simulated MMW, IR and metal detector outputs for security portal scenarios"};
  app.set_version_flag("--version", std::string("portalsim ") + PORTALSIM_VERSION);
  app.require_subcommand(1);
  std::map<std::string, std::function<int()>> commands;
  for (const auto& [name, add] : kCommands) commands[name] = add(app);
  for (const auto& [name, add] : more) commands[name] = add(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kUsage;
  }
  try {
    check_values(app);
  } catch (const InputError& e) {
    return fail(e.what(), kUsage);
  }
  const CLI::App* command = nullptr;
  try {
    for (const auto& [name, fn] : commands)
      if (app.got_subcommand(name)) {
        command = app.get_subcommand(name);
        return fn();
      }
  } catch (const InputError& e) {
    return fail(e.what(), names_an_argument(e.what(), command) ? kUsage : kBadInput);
  } catch (const OutputError& e) {
    return fail(e.what(), kOutput);
  } catch (const EnvironmentError& e) {
    return fail(e.what(), kEnvironment);
  } catch (const std::exception& e) {
    return fail(e.what(), kInternal);
  }
  return kInternal;
}

}  // namespace portalsim::cli
