#include "backend/compare.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <tuple>

namespace portalsim {

namespace {
ImageDiff compare_images(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, size_t per_image) {
  ImageDiff e;
  if (a.empty() || a.size() != b.size() || per_image == 0) return e;
  double total_sq = 0;
  size_t off1 = 0, differ = 0;
  const size_t images = a.size() / per_image;
  for (size_t i = 0; i < images; ++i) {
    double sq = 0;
    for (size_t p = i * per_image; p < (i + 1) * per_image; ++p) {
      const int d = std::abs(int(a[p]) - int(b[p]));
      e.max_abs = std::max(e.max_abs, d);
      sq += double(d) * d;
      off1 += d > 1;
      differ += d > 0;
    }
    const double rmse = std::sqrt(sq / per_image);
    e.rmse_mean += rmse / images;
    e.rmse_max = std::max(e.rmse_max, rmse);
    total_sq += sq;
  }
  e.pixels = a.size();
  const double mse = total_sq / a.size();
  e.psnr = mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 999.0;
  e.share_off_by_more_than_1 = double(off1) / a.size();
  e.share_differing = double(differ) / a.size();
  return e;
}
}  // namespace

OutputDiff compare_outputs(const BatchOutput& test, const BatchOutput& ref) {
  OutputDiff e;
  const size_t mmw_px = size_t(ref.mmw_width) * ref.mmw_height;
  if (!ref.upper.empty() && !test.upper.empty()) {
    std::vector<uint8_t> a(test.upper), b(ref.upper);
    a.insert(a.end(), test.lower.begin(), test.lower.end());
    b.insert(b.end(), ref.lower.begin(), ref.lower.end());
    e.mmw = compare_images(a, b, mmw_px);
  }
  e.ir = compare_images(test.ir, ref.ir, size_t(ref.ir_width) * ref.ir_height);
  for (auto [a, b, d] : {std::tuple{&test.upper, &ref.upper, &e.mmw}, std::tuple{&test.ir, &ref.ir, &e.ir}})
    if (a->size() != b->size()) d->max_abs = 256;  // one side has images the other lacks
  constexpr double kBroken = std::numeric_limits<double>::infinity();
  if (test.features.size() != ref.features.size()) {
    e.feature_max_abs = e.feature_mean_abs = kBroken;  // a missing or misshapen table is no match
  } else if (!ref.features.empty()) {
    for (size_t k = 0; k < ref.features.size(); ++k) {
      double d = std::abs(double(test.features[k]) - double(ref.features[k]));
      if (std::isnan(d)) d = kBroken;
      e.feature_max_abs = std::max(e.feature_max_abs, d);
      e.feature_mean_abs += d / ref.features.size();
    }
  }
  if (test.metal.size() != ref.metal.size()) {
    e.metal_exact = 0;
  } else if (!ref.metal.empty()) {
    size_t same = 0;
    for (size_t i = 0; i < ref.n; ++i)
      same += std::equal(test.metal.begin() + i * 19, test.metal.begin() + (i + 1) * 19, ref.metal.begin() + i * 19);
    e.metal_exact = ref.n ? double(same) / ref.n : 1.0;
  }
  return e;
}

}  // namespace portalsim
