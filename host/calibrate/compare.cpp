#include "calibrate/compare.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "backend/reference/stages.h"

namespace portalsim::calibrate {

namespace {

constexpr int kEdgeReach = 24;

std::vector<double> histogram(const std::vector<std::vector<uint8_t>>& images) {
  std::vector<double> h(256, 0.0);
  double n = 0;
  for (const auto& img : images)
    for (uint8_t v : img) {
      h[v] += 1;
      n += 1;
    }
  for (double& v : h) v /= std::max(1.0, n);
  return h;
}

// Mean periodogram of the rows of (image - clean), every 4th row; DFT by its definition.
std::vector<double> noise_power(const std::vector<std::vector<uint8_t>>& images,
                                const std::vector<std::vector<uint8_t>>& clean, int width, int height) {
  const int bins = width / 2 + 1;
  std::vector<double> p(bins, 0.0);
  std::vector<double> cs(static_cast<size_t>(bins) * width), sn(cs.size()), row(width);
  for (int f = 0; f < bins; ++f)
    for (int x = 0; x < width; ++x) {
      cs[static_cast<size_t>(f) * width + x] = std::cos(2 * M_PI * f * x / width);
      sn[static_cast<size_t>(f) * width + x] = std::sin(2 * M_PI * f * x / width);
    }
  double rows = 0;
  for (size_t i = 0; i < images.size(); ++i)
    for (int y = 0; y < height; y += 4) {
      double mean = 0;
      for (int x = 0; x < width; ++x) {
        const size_t at = static_cast<size_t>(y) * width + x;
        row[x] = double(images[i][at]) - clean[i][at];
        mean += row[x] / width;
      }
      for (int f = 0; f < bins; ++f) {
        double re = 0, im = 0;
        for (int x = 0; x < width; ++x) {
          re += (row[x] - mean) * cs[static_cast<size_t>(f) * width + x];
          im -= (row[x] - mean) * sn[static_cast<size_t>(f) * width + x];
        }
        p[f] += (re * re + im * im) / width;
      }
      rows += 1;
    }
  for (double& v : p) v /= std::max(1.0, rows);
  return p;
}

// The mean profile of `images` across the left outline that each `clean` image shows.
std::vector<double> edge_profile(const std::vector<std::vector<uint8_t>>& images,
                                 const std::vector<std::vector<uint8_t>>& clean, int width, int height) {
  std::vector<double> sum(2 * kEdgeReach + 1, 0.0), n(2 * kEdgeReach + 1, 0.0);
  for (size_t i = 0; i < images.size(); ++i) {
    const auto& c = clean[i];
    // Room and body as the noise-free image's darkest and brightest tenths.
    std::vector<uint8_t> sorted(c);
    std::sort(sorted.begin(), sorted.end());
    const double room = sorted[sorted.size() / 10], body = sorted[sorted.size() * 9 / 10];
    if (body - room < 2) continue;
    const double half = (room + body) / 2;
    for (int y = height / 3; y < 2 * height / 3; ++y) {
      int edge = -1;
      for (int x = 1; x < width && edge < 0; ++x)
        if ((c[static_cast<size_t>(y) * width + x - 1] < half) != (c[static_cast<size_t>(y) * width + x] < half))
          edge = x;
      if (edge < 0) continue;
      for (int d = -kEdgeReach; d <= kEdgeReach; ++d) {
        const int x = edge + d;
        if (x < 0 || x >= width) continue;
        sum[d + kEdgeReach] += images[i][static_cast<size_t>(y) * width + x];
        n[d + kEdgeReach] += 1;
      }
    }
  }
  for (size_t k = 0; k < sum.size(); ++k) sum[k] = n[k] > 0 ? sum[k] / n[k] : NAN;
  return sum;
}

nlohmann::json finite_or_null(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
  return a;
}

}  // namespace

Simulated simulate_captures(const Captures& captures, const CameraFit& fit, const Catalogue& cat,
                            const AssetSet& assets, const ModelSettings& model, uint64_t seed) {
  const Catalogue fc = fitted_catalogue(cat, fit);
  ModelSettings m = fitted_model(model, fit);
  m.seed = seed;
  Simulated out;
  for (const ViewCaptures& v : captures.views) {
    const int view = fc.sensor_index(v.name);
    // The view's own raw grid and NETD where the fit gives it a camera of its own, as
    // generate takes them from camera.catalogue.toml.
    const ModelSettings mv = m.for_view(fc.sensors[view]);
    std::map<int, reference::Field> raw;  // each subject's blurred raw grid, made once
    std::vector<std::vector<uint8_t>> noisy, clean;
    for (size_t c = 0; c < captures.count(); ++c) {
      Scenario s;
      s.subject = fit.subject[c];
      const reference::ViewScene vs = reference::view_scene(fc, assets, mv, view, s, c);
      if (!raw.count(s.subject)) {
        reference::Field f;
        reference::radiometry(vs, f);
        reference::optics(vs, f);
        reference::sample(vs, f);
        raw[s.subject] = std::move(f);
      }
      for (bool noise : {true, false}) {
        reference::Field f = raw[s.subject];
        if (noise) reference::netd(vs, f);
        reference::mmw_display(vs, f);
        std::vector<uint8_t> img(f.v.size());
        for (size_t k = 0; k < img.size(); ++k) img[k] = static_cast<uint8_t>(f.v[k]);
        (noise ? noisy : clean).push_back(std::move(img));
      }
    }
    out.noisy.push_back(std::move(noisy));
    out.clean.push_back(std::move(clean));
  }
  return out;
}

nlohmann::json compare_statistics(const Captures& captures, const Simulated& sim) {
  nlohmann::json j = nlohmann::json::object();
  for (size_t v = 0; v < captures.views.size(); ++v) {
    const ViewCaptures& vc = captures.views[v];
    const auto& clean = sim.clean[v];
    j[vc.name] = {{"histogram", {{"real", histogram(vc.images)}, {"sim", histogram(sim.noisy[v])}}},
                  {"noise_power",
                   {{"real", noise_power(vc.images, clean, vc.width, vc.height)},
                    {"sim", noise_power(sim.noisy[v], clean, vc.width, vc.height)}}},
                  {"edge_profile",
                   {{"offset_from", -kEdgeReach},
                    {"real", finite_or_null(edge_profile(vc.images, clean, vc.width, vc.height))},
                    {"sim", finite_or_null(edge_profile(sim.noisy[v], clean, vc.width, vc.height))}}}};
  }
  return j;
}

}  // namespace portalsim::calibrate
