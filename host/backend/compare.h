// How far one backend's outputs are from another's: the error measures of the parity
// tests and of `portalsim tradeoff`.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "backend/backend.h"
#include "plan/tolerance.h"

namespace portalsim {

struct ImageDiff {
  int max_abs = 0;       // gray levels (IR: temperature index)
  double mean_abs = 0;   // over all pixels
  double rmse_mean = 0;  // mean over images of each image's RMSE
  double rmse_max = 0;   // worst image's RMSE
  double psnr = 0;       // over all pixels, dB (infinite when identical: reported as 999)
  double share_off_by_more_than_1 = 0;
  double share_differing = 0;
  size_t pixels = 0;
};

struct OutputDiff {
  // Per camera kind (camera_kinds()' order), over all its views.
  std::vector<ImageDiff> cameras = std::vector<ImageDiff>(camera_kinds().size());
  const ImageDiff& of(Camera c) const { return cameras.at(static_cast<size_t>(c)); }
  double feature_max_abs = 0, feature_mean_abs = 0;
  double metal_exact = 1;      // share of scenarios whose zones all match
  bool features_only = false;  // the test run rendered no images: its features came from a features-only path
};

// Compares what both outputs hold (images, features, metal); `test` against `ref`. A test
// run without images (a features-only run) is compared on its features and metal only.
OutputDiff compare_outputs(const BatchOutput& test, const BatchOutput& ref);

// Empty when `d` is within `t` (features checked only where present, against the bounds of
// a features-only run where `d` compares one); else what broke.
std::string check_tolerance(const OutputDiff& d, const Tolerance& t);

// Two samples side by side: their moments and the Kolmogorov-Smirnov distance between
// their empirical distributions (b empty: between a's and the standard normal's).
struct SampleComparison {
  double mean_a = 0, mean_b = 0, sd_a = 0, sd_b = 0;
  double ks = 0;  // sup |F_a - F_b|
  // Where two independent samples of one distribution give a larger ks with
  // probability 0.001 (one sample: against the normal).
  double ks_critical = 0;
};
SampleComparison compare_samples(std::vector<double> a, std::vector<double> b = {});

// A sample's distribution against the standard normal: its moments and the KS distance.
struct Distribution {
  double mean = 0, sd = 0, skewness = 0, excess_kurtosis = 0;
  double ks = 0, ks_critical = 0;  // as compare_samples(v)
};
Distribution distribution(const std::vector<double>& v);

}  // namespace portalsim
