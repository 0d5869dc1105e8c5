// How far one backend's outputs are from another's: the error measures of the parity
// tests and of `portalsim tradeoff`.
#pragma once
#include <cstddef>
#include <string>

#include "backend/backend.h"
#include "plan/tolerance.h"

namespace portalsim {

struct ImageDiff {
  int max_abs = 0;       // gray levels (IR: temperature index)
  double rmse_mean = 0;  // mean over images of each image's RMSE
  double rmse_max = 0;   // worst image's RMSE
  double psnr = 0;       // over all pixels, dB (infinite when identical: reported as 999)
  double share_off_by_more_than_1 = 0;
  double share_differing = 0;
  size_t pixels = 0;
};

struct OutputDiff {
  ImageDiff mmw, ir;
  double feature_max_abs = 0, feature_mean_abs = 0;
  double metal_exact = 1;  // share of scenarios whose 19 zones all match
};

// Compares what both outputs hold (images, features, metal); `test` against `ref`.
OutputDiff compare_outputs(const BatchOutput& test, const BatchOutput& ref);

// Empty when `d` is within `t` (features checked only where present); else what broke.
std::string check_tolerance(const OutputDiff& d, const Tolerance& t);

}  // namespace portalsim
