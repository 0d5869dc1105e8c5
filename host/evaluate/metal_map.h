// A walk-through metal detector's sensitivity map, as NIJ 0601.02, ASTM F1468 and ASTM
// F3566-22 test one (docs/model/metal.md, "Sensitivity maps"): a test object carried through
// the physics model's portal at a grid of lateral positions and heights, along each of three
// orientations, walking along the passage sampled in time; each zone reads the peak of its
// time series. The alarm level is set from clean testers (the subjects without metal, and
// with --clean-testers benign also each subject with one benign item in each region) within a
// stated false-alarm rate; benign items' nuisance-alarm rates are reported at each
// sensitivity setting.
#pragma once
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/catalogue.h"

namespace portalsim {
class OpenCLRuntime;
}

namespace portalsim::evaluate {

// The map's settings; each is checked by check_metal_map naming its flag.
struct MetalMapSettings {
  std::string object;                           // --metal-map: a catalogue name or alias
  double grid_step = 0.05;                      // --grid-step, metres between cells across and up
  double speed = 1.0;                           // --speed, m/s: the standards' walking pace, about 1 m/s
  double sample_rate = 50.0;                    // --sample-rate, Hz: the detector's zone readings a second (assumed)
  double walk = 1.0;                            // metres walked either side of the coils' plane (assumed: fields 1/r^3)
  int passes = 200;                             // --passes: noisy passes a cell
  double pfa = 0.01;                            // --clean-pfa: clean testers' false-alarm rate at most
  bool benign_clean = false;                    // --clean-testers benign: the benign items' carriers count as clean too
  std::vector<int> settings = {150, 180, 195};  // --sensitivity: alarm levels to report
  int metal_noise = 3;                          // --metal-noise: the detector's triangular noise, counts
  uint64_t seed = 0;                            // --seed
  unsigned threads = 0;                         // 0: every core
};

// Throws InputError naming the flag of the first bad setting (an unknown object, a grid with
// no cell, speed or sample rate not above 0, Pfa outside 0..1, ...).
void check_metal_map(const Catalogue& cat, const MetalMapSettings& s);

// The map's walks: each a series of places of one object (a probe record a sample,
// kernels/contract.h PS_MP_*), over the object records of PS_MV_LEN doubles.
struct MetalWalks {
  std::vector<double> objects;  // records PS_MV_*
  std::vector<double> probes;   // records PS_MP_*: walks x samples
  size_t walks = 0, samples = 0;
};

// The test object's walks (orientation-major, then cells z-major: z row by row, x along
// each), unreachable cells included, then the clean testers' (subject-major, then benign
// item, then region).
MetalWalks metal_map_walks(const Catalogue& cat, const MetalMapSettings& s);

// Runs the map: the responses through the OpenCL kernels where `rt` is given, else the fp64
// reference; the noise drawn on the host (stream PS_STREAM_METAL_MAP). Returns the report
// (docs/reference/outputs.md, metal_map.json). Byte-identical for the same settings.
nlohmann::json metal_map(const Catalogue& cat, const MetalMapSettings& s, OpenCLRuntime* rt);

// metal_map.md from the report.
std::string metal_map_markdown(const nlohmann::json& report);

// The standards' benign items the map looks for in the catalogue (names or aliases).
inline constexpr std::array<const char*, 8> kBenignItems{"keys",    "coins", "belt-buckle", "mobile-phone",
                                                         "glasses", "watch", "pendant",     "compact-disk"};

}  // namespace portalsim::evaluate
