// `portalsim validate --demo`: a simulated set and a "real" one made through the user-image
// route (a catalogue whose subjects' MMW images are files, altered as another camera would
// see them), so that a user without captures sees the whole report.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace portalsim::cli {

inline constexpr uint64_t kDemoCount = 200;  // scenarios per set: the demo runs in seconds

// Makes folder `dir` (must not exist) holding images/ (the built-in subjects' MMW views as
// `portalsim catalogue --images` writes them, then blurred, gain-changed and noised),
// catalogue.toml (the built-in catalogue with those files as the subjects' MMW images),
// sim.arff and real.arff (thesis case 2, `count` scenarios each, seeds `seed` and seed + 1,
// block means of side `block`; the real set through the altered catalogue). Returns {"sim": path, "real": path,
// "about": what was made}.
nlohmann::json make_demo_sets(const std::string& dir, uint64_t count, uint64_t seed, int block);

}  // namespace portalsim::cli
