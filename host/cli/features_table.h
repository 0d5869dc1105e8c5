// Scenario folders (simulated or real captures) to a feature table: the code behind
// `portalsim features`, shared with `portalsim validate` (which accepts folders too).
#pragma once
#include <string>
#include <vector>

namespace portalsim::cli {

struct FeaturesCount {
  size_t rows = 0, positive = 0;
};

// Writes the table of `folders` (scenario folders, or folders holding them) to `out` as
// arff, csv or npy, with block means of side `block` and the regions of `catalogue` (empty:
// the built-in one). `out` must not exist; nothing is left behind on failure.
FeaturesCount write_features(const std::vector<std::string>& folders, const std::string& out, const std::string& format,
                             int block, const std::string& catalogue);

// The block side for `--grid WxH` ("5x5": the thesis's grid of block means per view) with
// the views of `catalogue` (empty: the built-in one). Throws InputError naming --grid when
// the text is not WxH or no square block cuts every pooled view into W x H blocks.
int block_for_grid(const std::string& grid, const std::string& catalogue);

}  // namespace portalsim::cli
