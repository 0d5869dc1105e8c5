// A folder of MMW captures read for `portalsim calibrate`: the thesis's layout of one
// folder per scenario (upper.png, lower.png, as `simulate --out` and `generate --what
// images` write them) or a data.h5 of `generate --format h5`. Every check that can refuse
// the input is made here, before anything is fitted or written.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "scene/catalogue.h"

namespace portalsim::calibrate {

// Fewer captures than this cannot tell the scene's spread from the camera's noise.
inline constexpr size_t kMinCaptures = 4;

// One camera view's captures: same size, gray, one per scenario.
struct ViewCaptures {
  std::string name;  // the catalogue's view: "upper", "lower"
  int width = 0, height = 0;
  std::vector<std::vector<uint8_t>> images;  // row-major gray levels
  std::vector<std::string> files;            // where each came from, for messages
};

struct Captures {
  std::string source;               // the folder or data.h5 as given
  std::vector<ViewCaptures> views;  // the catalogue's MMW views, in its order
  size_t count() const { return views.empty() ? 0 : views[0].images.size(); }
};

// The catalogue's MMW views, in its order: what calibrate fits.
std::vector<std::string> mmw_views(const Catalogue& cat);

// Reads DIR: DIR/data.h5 if it is there (or DIR is a data.h5), else every scenario folder
// under DIR (DIR/images/<index>/ for a `generate` run, or DIR/<name>/), each with a PNG of
// every MMW view of `cat` (upper.png and lower.png for the built-in portal). Throws
// InputError naming the file: missing views, colour where gray is expected, sizes that
// differ, fewer than kMinCaptures, or a flat image (one gray level throughout) among
// captures that are not all flat.
Captures read_captures(const std::string& dir, const Catalogue& cat);

// The checks read_captures makes, on captures already in memory (data from elsewhere).
void check_captures(const Captures& c);

}  // namespace portalsim::calibrate
