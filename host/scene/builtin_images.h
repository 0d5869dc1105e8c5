// What a catalogue may name without giving image files: the shapes and noise patterns
// that assets/procedural*.cpp draw. Declared here so the catalogue can be checked
// without the drawing code; tests/procedural_test.cpp holds the two lists equal.
#pragma once
#include <algorithm>
#include <array>
#include <string_view>

namespace portalsim {

inline constexpr std::array<std::string_view, 20> kProceduralShapes = {
    "gun",  "handle", "rod",   "disk", "strip", "plate",  "pendant", "pipe",    "buckle", "tile",
    "slab", "phone",  "knife", "keys", "coins", "wallet", "watch",   "glasses", "bottle", "sheet"};

inline bool is_procedural_shape(std::string_view name) {
  return std::find(kProceduralShapes.begin(), kProceduralShapes.end(), name) != kProceduralShapes.end();
}

// Noise patterns 0 .. kProceduralNoisePatterns-1 have a drawn default.
inline constexpr int kProceduralNoisePatterns = 5;

}  // namespace portalsim
