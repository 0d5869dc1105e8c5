#include "backend/compare.h"

#include <algorithm>
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
      e.mean_abs += d;
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
  e.mean_abs /= double(a.size());
  const double mse = total_sq / a.size();
  e.psnr = mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 999.0;
  e.share_off_by_more_than_1 = double(off1) / a.size();
  e.share_differing = double(differ) / a.size();
  return e;
}
}  // namespace

OutputDiff compare_outputs(const BatchOutput& test, const BatchOutput& ref) {
  OutputDiff e;
  // Buffers come sized from the plan (prepare_output), so only a plan without images
  // leaves every view empty.
  e.features_only = !test.features.empty() &&
                    std::all_of(test.views.begin(), test.views.end(), [](const ViewImages& v) { return v.empty(); });
  // Per camera, over all its views: a view one side has and the other lacks is no match.
  for (const CameraKind* kind : camera_kinds()) {
    if (e.features_only) break;
    const Camera cam = kind->camera;
    std::vector<uint8_t> a, b;
    size_t per_image = 0;
    bool mismatch = test.views.size() != ref.views.size();
    for (size_t k = 0; k < ref.views.size() && k < test.views.size(); ++k) {
      if (ref.views[k].camera != cam) continue;
      mismatch |= test.views[k].pixels.size() != ref.views[k].pixels.size();
      if (ref.views[k].empty() || test.views[k].empty()) continue;
      // Images of equal size compare together; IR and MMW views differ in size.
      per_image = ref.views[k].pixels_per_image();
      a.insert(a.end(), test.views[k].pixels.begin(), test.views[k].pixels.end());
      b.insert(b.end(), ref.views[k].pixels.begin(), ref.views[k].pixels.end());
    }
    ImageDiff& d = e.cameras[static_cast<size_t>(cam)];
    d = compare_images(a, b, per_image);
    if (mismatch) d.max_abs = 256;
  }
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

std::string check_tolerance(const OutputDiff& d, const Tolerance& t) {
  std::string why;
  for (const CameraKind* kind : camera_kinds()) {
    const char* name = kind->label;
    const ImageDiff* img = &d.of(kind->camera);
    if (img->mean_abs > t.pixel_mean_abs)
      why += std::string(name) + " mean abs " + std::to_string(img->mean_abs) + " > " +
             std::to_string(t.pixel_mean_abs) + "; ";
    if (img->max_abs > t.pixel_max_abs)
      why += std::string(name) + " max abs " + std::to_string(img->max_abs) + " > " + std::to_string(t.pixel_max_abs) +
             "; ";
    if (img->share_differing > t.pixel_share_differing)
      why += std::string(name) + " share differing " + std::to_string(img->share_differing) + " > " +
             std::to_string(t.pixel_share_differing) + "; ";
  }
  const double max_abs = d.features_only ? t.features_only_max_abs : t.feature_max_abs;
  const double mean_abs = d.features_only ? t.features_only_mean_abs : t.feature_mean_abs;
  const std::string run = d.features_only ? "features-only run: " : "";
  if (d.feature_max_abs > max_abs)
    why += run + "feature max abs " + std::to_string(d.feature_max_abs) + " > " + std::to_string(max_abs) + "; ";
  if (d.feature_mean_abs > mean_abs)
    why += run + "feature mean abs " + std::to_string(d.feature_mean_abs) + " > " + std::to_string(mean_abs) + "; ";
  if (d.metal_exact < 1.0) why += "metal zones differ; ";
  return why;
}

namespace {
void moments(const std::vector<double>& v, double& mean, double& sd) {
  double sum = 0, sq = 0;
  for (double x : v) sum += x;
  mean = v.empty() ? 0 : sum / v.size();
  for (double x : v) sq += (x - mean) * (x - mean);
  sd = v.size() > 1 ? std::sqrt(sq / (v.size() - 1)) : 0;
}
}  // namespace

SampleComparison compare_samples(std::vector<double> a, std::vector<double> b) {
  SampleComparison c;
  moments(a, c.mean_a, c.sd_a);
  moments(b, c.mean_b, c.sd_b);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  const double na = double(a.size()), nb = double(b.size());
  // c(0.001) = sqrt(-ln(0.0005) / 2) = 1.949 (Smirnov's asymptotic distribution).
  constexpr double kC = 1.949;
  if (b.empty()) {
    for (size_t i = 0; i < a.size(); ++i) {
      const double f = 0.5 * std::erfc(-a[i] / std::sqrt(2.0));
      c.ks = std::max({c.ks, std::abs(f - i / na), std::abs((i + 1) / na - f)});
    }
    c.ks_critical = kC / std::sqrt(na);
    return c;
  }
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] <= x) ++i;
    while (j < b.size() && b[j] <= x) ++j;
    c.ks = std::max(c.ks, std::abs(i / na - j / nb));
  }
  c.ks_critical = kC * std::sqrt((na + nb) / (na * nb));
  return c;
}

Distribution distribution(const std::vector<double>& v) {
  Distribution d;
  const SampleComparison c = compare_samples(v);
  d.mean = c.mean_a;
  d.sd = c.sd_a;
  d.ks = c.ks;
  d.ks_critical = c.ks_critical;
  double m2 = 0, m3 = 0, m4 = 0;
  for (double x : v) {
    const double e = x - d.mean, e2 = e * e;
    m2 += e2;
    m3 += e2 * e;
    m4 += e2 * e2;
  }
  if (v.empty() || m2 == 0) return d;
  const double n = double(v.size());
  m2 /= n;
  d.skewness = m3 / n / std::pow(m2, 1.5);
  d.excess_kurtosis = m4 / n / (m2 * m2) - 3;
  return d;
}

}  // namespace portalsim
