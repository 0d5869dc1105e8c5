#include "cli/commands.h"
#include "speed/bench_command.h"

int main(int argc, char** argv) { return portalsim::cli::run(argc, argv, {{"bench", portalsim::speed::add_bench}}); }
