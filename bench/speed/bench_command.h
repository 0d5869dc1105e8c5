// portalsim bench: the speed table of the machine it runs on, on any OpenCL device
// (docs/guide/bench.md). Registered by tools/portalsim.cpp, outside the core library,
// because it links the plain loops of bench/baseline/.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>

namespace portalsim::speed {

std::function<int()> add_bench(CLI::App& app);

}  // namespace portalsim::speed
