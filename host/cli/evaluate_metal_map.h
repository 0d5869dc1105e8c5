// `portalsim evaluate --metal-map OBJECT`: the walk-through metal detector's sensitivity map
// (host/evaluate/metal_map.h) written as a report folder.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>

namespace portalsim::cli {

// Adds --metal-map and its options to `evaluate`, and the options it shares with the rest of
// evaluate (--out, --seed, --catalogue, --assets, --backend, --device, --metal-noise,
// --threads, --no-plot) where `evaluate` has none yet. The function returned runs the map and
// returns its exit status where --metal-map was given, and nullopt where it was not.
std::function<std::optional<int>()> add_metal_map(CLI::App& evaluate);

}  // namespace portalsim::cli
