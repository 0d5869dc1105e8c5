#include "cli/commands.h"

int main(int argc, char** argv) { return portalsim::cli::run(argc, argv); }
