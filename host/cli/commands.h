// The subcommands of the portalsim command line.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <string>

namespace portalsim::cli {

// Each registers its subcommand and returns the function that runs it (exit status).
std::function<int()> add_simulate(CLI::App& app);
std::function<int()> add_catalogue(CLI::App& app);
std::function<int()> add_generate(CLI::App& app);
std::function<int()> add_features(CLI::App& app);
std::function<int()> add_tradeoff(CLI::App& app);
std::function<int()> add_serve(CLI::App& app);
std::function<int()> add_validate(CLI::App& app);
std::function<int()> add_transfer(CLI::App& app);
std::function<int()> add_knobs(CLI::App& app);
std::function<int()> add_merge(CLI::App& app);
std::function<int()> add_calibrate(CLI::App& app);
std::function<int()> add_evaluate(CLI::App& app);

// Whether run() prints the error a command fails with (an MPI rank other than 0 does not:
// rank 0 prints every rank's).
void print_errors(bool on);

// Registers a subcommand and returns the function that runs it, as the add_* above.
using AddCommand = std::function<std::function<int()>(CLI::App&)>;

// Parses argv and runs the chosen subcommand; prints errors, returns the exit status.
// `more`: subcommands by name from outside this library (tools/portalsim.cpp adds
// `bench`, whose plain loops are in bench/, not in the core that Python links).
int run(int argc, char** argv, const std::map<std::string, AddCommand>& more = {});

}  // namespace portalsim::cli
