#include "calibrate/fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "backend/reference/stages.h"
#include "base/error.h"
#include "base/spoken_list.h"

namespace portalsim::calibrate {

namespace {

constexpr double kFwhmPerSigma = 2.3548200450309493;  // 2 sqrt(2 ln 2)

// Optics then sampling along one axis as a raw x size matrix: the PSF's Gaussian as
// reference::gaussian_blur takes it (truncated at 4 sigma, normalised, edges held), then
// each raw pixel's mean over its footprint as reference::sample takes it.
std::vector<double> optics_sampling(int size, int raw, double sigma) {
  std::vector<double> blur(static_cast<size_t>(size) * size, 0.0);
  if (sigma <= 0) {
    for (int x = 0; x < size; ++x) blur[static_cast<size_t>(x) * size + x] = 1.0;
  } else {
    const int R = static_cast<int>(std::ceil(4.0 * sigma));
    std::vector<double> tap(2 * R + 1);
    double total = 0;
    for (int d = -R; d <= R; ++d) total += tap[d + R] = std::exp(-0.5 * d * d / (sigma * sigma));
    for (int x = 0; x < size; ++x)
      for (int d = -R; d <= R; ++d)
        blur[static_cast<size_t>(x) * size + std::clamp(x + d, 0, size - 1)] += tap[d + R] / total;
  }
  const double s = double(size) / raw;
  std::vector<double> k(static_cast<size_t>(raw) * size, 0.0);
  for (int c = 0; c < raw; ++c)
    for (int x = 0; x < size; ++x) {
      const double w = std::max(0.0, std::min(x + 1.0, (c + 1) * s) - std::max(double(x), c * s)) / s;
      if (w == 0) continue;
      for (int j = 0; j < size; ++j)
        k[static_cast<size_t>(c) * size + j] += w * blur[static_cast<size_t>(x) * size + j];
    }
  return k;
}

// One capture's view: its recovered raw cells that no clipped pixel reaches.
struct Cells {
  std::vector<double> value;
  std::vector<int> index;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

// Least squares y = a + b x over the pairs, then again without those beyond 2.5 robust
// sigmas (objects on the subject, which the bare subject does not show).
struct Line {
  double a = 0, b = 0, se_b = 0;
};
Line robust_line(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<char> keep(x.size(), 1);
  Line l;
  for (int pass = 0; pass < 2; ++pass) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < x.size(); ++i)
      if (keep[i]) {
        n += 1;
        sx += x[i];
        sy += y[i];
        sxx += x[i] * x[i];
        sxy += x[i] * y[i];
      }
    const double vx = sxx - sx * sx / n;
    l.b = vx > 1e-12 ? (sxy - sx * sy / n) / vx : 0.0;
    l.a = (sy - l.b * sx) / n;
    std::vector<double> r(x.size());
    for (size_t i = 0; i < x.size(); ++i) r[i] = std::abs(y[i] - l.a - l.b * x[i]);
    const double scale = 1.4826 * median(r);
    double ss = 0, m = 0;
    for (size_t i = 0; i < x.size(); ++i)
      if (keep[i]) {
        ss += r[i] * r[i];
        m += 1;
      }
    l.se_b = vx > 1e-12 ? std::sqrt(ss / std::max(1.0, m - 2) / vx) : INFINITY;
    if (pass == 0)
      for (size_t i = 0; i < x.size(); ++i) keep[i] = r[i] <= 2.5 * scale + 1e-9;
  }
  return l;
}

// The mean of the smallest 90% of the squares: objects leave the rest.
double trimmed_ms(std::vector<double> sq) {
  if (sq.empty()) return 0;
  std::sort(sq.begin(), sq.end());
  const size_t n = std::max<size_t>(1, sq.size() * 9 / 10);
  double s = 0;
  for (size_t i = 0; i < n; ++i) s += sq[i];
  return s / n;
}

struct Problem {
  const Captures& cap;
  std::vector<std::array<int, 2>> raw;                // [view] its raw grid
  std::vector<std::vector<reference::Field>> kelvin;  // [subject][view] bare subject, K
  std::vector<std::vector<Cells>> cells;              // [capture][view]
};

struct Evaluation {
  double cost = INFINITY;
  Line line;
  std::vector<int> subject;
  std::vector<double> x, y;           // every cell: the subject's kelvin and the capture's gray
  std::vector<int> view_of, capture;  // and whose cell it is
  size_t pairs = 0;
};

// Each subject's bare raw grid, K, under a PSF of `fwhm` view pixels.
std::vector<std::vector<std::vector<double>>> predictions(const Problem& p, double fwhm) {
  std::vector<std::vector<std::vector<double>>> out(p.kelvin.size());
  for (size_t v = 0; v < p.cap.views.size(); ++v) {
    const int W = p.cap.views[v].width, H = p.cap.views[v].height;
    const int raw_w = p.raw[v][0], raw_h = p.raw[v][1];
    const std::vector<double> kx = optics_sampling(W, raw_w, fwhm / kFwhmPerSigma);
    const std::vector<double> ky = optics_sampling(H, raw_h, fwhm / kFwhmPerSigma);
    // Where each raw column's weights are not zero.
    std::vector<std::pair<int, int>> xs(raw_w, {W, 0});
    for (int c = 0; c < raw_w; ++c)
      for (int x = 0; x < W; ++x)
        if (kx[static_cast<size_t>(c) * W + x] != 0) xs[c] = {std::min(xs[c].first, x), x + 1};
    for (size_t j = 0; j < p.kelvin.size(); ++j) {
      const reference::Field& t = p.kelvin[j][v];
      std::vector<double> mid(static_cast<size_t>(H) * raw_w, 0.0);
      for (int y = 0; y < H; ++y)
        for (int c = 0; c < raw_w; ++c) {
          double acc = 0;
          for (int x = xs[c].first; x < xs[c].second; ++x) acc += kx[static_cast<size_t>(c) * W + x] * t.at(x, y);
          mid[static_cast<size_t>(y) * raw_w + c] = acc;
        }
      std::vector<double> raw(static_cast<size_t>(raw_w) * raw_h, 0.0);
      for (int r = 0; r < raw_h; ++r)
        for (int y = 0; y < H; ++y) {
          const double w = ky[static_cast<size_t>(r) * H + y];
          if (w == 0) continue;
          for (int c = 0; c < raw_w; ++c)
            raw[static_cast<size_t>(r) * raw_w + c] += w * mid[static_cast<size_t>(y) * raw_w + c];
        }
      out[j].push_back(std::move(raw));
    }
  }
  return out;
}

Evaluation evaluate(const Problem& p, double fwhm) {
  const auto pred = predictions(p, fwhm);
  const size_t n = p.cap.count(), subjects = pred.size();
  Evaluation e;
  e.subject.assign(n, 0);
  // Start: each capture's own best line against each subject picks its subject.
  for (size_t c = 0; c < n; ++c) {
    double best = INFINITY;
    for (size_t j = 0; j < subjects; ++j) {
      std::vector<double> x, y;
      for (size_t v = 0; v < p.cells[c].size(); ++v)
        for (size_t k = 0; k < p.cells[c][v].index.size(); ++k) {
          x.push_back(pred[j][v][p.cells[c][v].index[k]]);
          y.push_back(p.cells[c][v].value[k]);
        }
      if (x.size() < 3) break;
      const Line l = robust_line(x, y);
      std::vector<double> sq;
      for (size_t i = 0; i < x.size(); ++i) sq.push_back(std::pow(y[i] - l.a - l.b * x[i], 2));
      const double cost = trimmed_ms(sq);
      if (cost < best) {
        best = cost;
        e.subject[c] = static_cast<int>(j);
      }
    }
  }
  // Then one window for all: fit it, re-match each capture under it, fit again.
  for (int round = 0; round < 3; ++round) {
    std::vector<double> x, y;
    std::vector<int> view_of, capture;
    for (size_t c = 0; c < n; ++c)
      for (size_t v = 0; v < p.cells[c].size(); ++v)
        for (size_t k = 0; k < p.cells[c][v].index.size(); ++k) {
          x.push_back(pred[e.subject[c]][v][p.cells[c][v].index[k]]);
          y.push_back(p.cells[c][v].value[k]);
          view_of.push_back(static_cast<int>(v));
          capture.push_back(static_cast<int>(c));
        }
    e.line = robust_line(x, y);
    e.pairs = x.size();
    if (round == 2) {
      std::vector<double> sq(x.size());
      for (size_t i = 0; i < x.size(); ++i) sq[i] = std::pow(y[i] - e.line.a - e.line.b * x[i], 2);
      e.cost = trimmed_ms(std::move(sq));
      e.x = std::move(x);
      e.y = std::move(y);
      e.view_of = std::move(view_of);
      e.capture = std::move(capture);
      break;
    }
    for (size_t c = 0; c < n; ++c) {
      double best = INFINITY;
      for (size_t j = 0; j < subjects; ++j) {
        std::vector<double> sq;
        for (size_t v = 0; v < p.cells[c].size(); ++v)
          for (size_t k = 0; k < p.cells[c][v].index.size(); ++k)
            sq.push_back(
                std::pow(p.cells[c][v].value[k] - e.line.a - e.line.b * pred[j][v][p.cells[c][v].index[k]], 2));
        const double cost = trimmed_ms(std::move(sq));
        if (cost < best) {
          best = cost;
          e.subject[c] = static_cast<int>(j);
        }
      }
    }
  }
  return e;
}

// Each view's raw grid from its own captures (a portal's cameras may differ), and which
// views' cameras the run's raw grid and noise come from.
void fit_view_grids(const Captures& captures, const Catalogue& cat, CameraFit& fit) {
  const ViewCaptures& v0 = captures.views[0];
  bool raw_view_found = false, noise_view_found = false;
  for (size_t k = 0; k < captures.views.size(); ++k) {
    const ViewCaptures& v = captures.views[k];
    const int s = cat.sensor_index(v.name);
    if (s < 0) throw InputError(captures.source + ": the catalogue has no camera view \"" + v.name + "\"");
    const Sensor& sensor = cat.sensors[s];
    if (sensor.width != v.width || sensor.height != v.height)
      throw InputError(v.files.front() + ": is " + std::to_string(v.width) + "x" + std::to_string(v.height) +
                       " but the catalogue's " + v.name + " view is " + std::to_string(sensor.width) + "x" +
                       std::to_string(sensor.height));
    if (v.width != v0.width || v.height != v0.height)
      throw InputError(v.files.front() + ": the views differ in size from " + v0.files.front());
    ViewFit vf;
    vf.name = v.name;
    std::vector<const std::vector<uint8_t>*> imgs;
    for (const auto& img : v.images) imgs.push_back(&img);
    vf.grid_x = raw_grid_axis(imgs, v.width, v.height, true);
    vf.grid_y = raw_grid_axis(imgs, v.width, v.height, false);
    vf.raw_w = vf.grid_x.raw;
    vf.raw_h = vf.grid_y.raw;
    fit.views.push_back(std::move(vf));
    // The run's camera is the first view's that the catalogue gives none of its own.
    if (!sensor.raw && !raw_view_found) {
      fit.raw_view = k;
      raw_view_found = true;
    }
    if (!sensor.netd && !noise_view_found) {
      fit.noise_view = k;
      noise_view_found = true;
    }
  }
  fit.raw_w = fit.views[fit.raw_view].raw_w;
  fit.raw_h = fit.views[fit.raw_view].raw_h;
}

// What the fit compares: each subject's bare radiometry per view, and up to about 1,024 valid
// raw cells per view of each capture.
Problem fit_problem(const Captures& captures, const Catalogue& cat, const AssetSet& assets, const ModelSettings& model,
                    const CameraFit& fit) {
  Problem p{captures, {}, {}, {}};
  for (const ViewFit& vf : fit.views) p.raw.push_back({vf.raw_w, vf.raw_h});
  ModelSettings m = model;
  m.model = Model::physics;
  for (size_t j = 0; j < cat.subjects.size(); ++j) {
    Scenario s;
    s.subject = static_cast<int>(j);
    std::vector<reference::Field> views;
    for (const ViewCaptures& v : captures.views) {
      const reference::ViewScene vs = reference::view_scene(cat, assets, m, cat.sensor_index(v.name), s, 0);
      reference::Field f;
      reference::radiometry(vs, f);
      views.push_back(std::move(f));
    }
    p.kelvin.push_back(std::move(views));
  }
  p.cells.resize(captures.count());
  for (size_t c = 0; c < captures.count(); ++c)
    for (size_t k = 0; k < captures.views.size(); ++k) {
      const ViewCaptures& v = captures.views[k];
      std::vector<double> raw;
      std::vector<char> valid;
      recover_raw(v.images[c], v.width, v.height, p.raw[k][0], p.raw[k][1], raw, valid);
      // At most about 1,024 cells a view: plenty for a robust fit, and the search stays quick
      // on a full-size raw grid.
      const size_t stride = std::max<size_t>(1, raw.size() / 1024);
      Cells cells;
      for (size_t k = 0; k < raw.size(); k += stride)
        if (valid[k]) {
          cells.value.push_back(raw[k]);
          cells.index.push_back(static_cast<int>(k));
        }
      p.cells[c].push_back(std::move(cells));
    }

  return p;
}

// The blur: a scan over the PSF's FWHM from a third of a pixel to 8 views wide, then a
// golden-section search around the best. Returns the evaluation at the best.
Evaluation fit_blur(const Problem& p, int width, CameraFit& fit) {
  const double lo = std::log(0.3), hi = std::log(8.0 * width);
  const int scan = 12;
  int best = 0;
  std::vector<double> us;
  for (int i = 0; i < scan; ++i) {
    const double u = lo + (hi - lo) * i / (scan - 1);
    const double cost = evaluate(p, std::exp(u)).cost;
    us.push_back(u);
    fit.blur_fwhm.push_back(std::exp(u));
    fit.blur_cost.push_back(cost);
    if (cost < fit.blur_cost[best]) best = i;
  }
  double a = us[std::max(0, best - 1)], b = us[std::min(scan - 1, best + 1)];
  const double g = (std::sqrt(5.0) - 1) / 2;
  double c1 = b - g * (b - a), c2 = a + g * (b - a);
  double f1 = evaluate(p, std::exp(c1)).cost, f2 = evaluate(p, std::exp(c2)).cost;
  for (int it = 0; it < 10; ++it) {  // the bracket to 1% of its width
    if (f1 < f2) {
      b = c2;
      c2 = c1;
      f2 = f1;
      c1 = b - g * (b - a);
      f1 = evaluate(p, std::exp(c1)).cost;
    } else {
      a = c1;
      c1 = c2;
      f1 = f2;
      c2 = a + g * (b - a);
      f2 = evaluate(p, std::exp(c2)).cost;
    }
  }
  fit.fwhm_pixels = std::exp((a + b) / 2);
  const Evaluation e = evaluate(p, fit.fwhm_pixels);
  // Told when the scan's widest PSF (everything spread over the view) fits clearly worse
  // than the best, and the best is not at the scan's end: otherwise the captures say only
  // that the blur is at least about this wide.
  fit.blur_told = fit.blur_cost.back() > 1.05 * e.cost + 1e-9 && best < scan - 1;
  return e;
}

// The window's gain and level against the evaluation e; returns the fitted offset.
double fit_window(const Evaluation& e, const ModelSettings& model, CameraFit& fit) {
  // The window's gain is told by the body against the room. Where the captures hardly
  // show that contrast (a blur wider than the view, a 1x1 raw grid), the model's window
  // width (its `window` knob) is kept and only its level is fitted.
  fit.gain = e.line.b;
  fit.gain_rel_error = e.line.se_b / std::abs(fit.gain);
  double offset = e.line.a;
  fit.window_told = fit.gain > 0 && std::isfinite(offset) && fit.gain_rel_error <= 0.1;
  if (!fit.window_told) {
    fit.gain = 255.0 / (model.window_hi - model.window_lo);
    std::vector<double> level(e.x.size());
    for (size_t i = 0; i < e.x.size(); ++i) level[i] = e.y[i] - fit.gain * e.x[i];
    offset = median(level);
  }
  fit.display_min = -offset / fit.gain;
  fit.display_max = fit.display_min + 255.0 / fit.gain;
  return offset;
}

void fit_noise(const Captures& captures, const Catalogue& cat, const Evaluation& e, double offset, CameraFit& fit) {
  // The noise: each view's robust spread of what the bare subject leaves, less its grid's
  // rounding; and each capture's alone, whose scatter gives the figure's standard error.
  const size_t V = captures.views.size(), n = captures.count();
  std::vector<std::vector<double>> absr(V);
  std::vector<std::vector<std::vector<double>>> by_capture(V, std::vector<std::vector<double>>(n));
  for (size_t i = 0; i < e.x.size(); ++i) {
    const double r = std::abs(e.y[i] - offset - fit.gain * e.x[i]);
    absr[e.view_of[i]].push_back(r);
    by_capture[e.view_of[i]][e.capture[i]].push_back(r);
  }
  const auto noise_of = [](std::vector<double> r, double round) {
    const double s = 1.4826 * median(std::move(r));
    return std::sqrt(std::max(0.0, s * s - round));
  };
  std::vector<double> round(V);
  for (size_t v = 0; v < V; ++v) {
    ViewFit& vf = fit.views[v];
    round[v] = rounding_variance(captures.views[v].width, captures.views[v].height, vf.raw_w, vf.raw_h);
    vf.noise_gray = noise_of(absr[v], round[v]);
    vf.netd = vf.noise_gray / fit.gain;
    vf.cells = static_cast<int>(absr[v].size());
    double sum = 0, sum2 = 0, k = 0;
    for (const std::vector<double>& r : by_capture[v])
      if (!r.empty()) {
        const double one = noise_of(r, round[v]);
        sum += one;
        sum2 += one * one;
        k += 1;
      }
    vf.noise_se = k > 1 ? std::sqrt(std::max(0.0, sum2 - sum * sum / k) / (k - 1) / k) : INFINITY;
  }
  // The run's noise is pooled over the views that agree with the run view's: one camera's
  // views share one NETD, fitted from all their cells.
  const ViewFit& ref = fit.views[fit.noise_view];
  std::vector<double> pooled;
  double pooled_round = 0;
  for (size_t v = 0; v < V; ++v) {
    ViewFit& vf = fit.views[v];
    const double gap = std::abs(vf.noise_gray - ref.noise_gray);
    vf.noise_agrees = v == fit.noise_view || gap <= kNoiseAgreement * std::hypot(vf.noise_se, ref.noise_se) ||
                      gap <= std::max(kNoiseTolerance * ref.noise_gray, kMinCameraNoiseGray);
    if (!vf.noise_agrees) continue;
    pooled.insert(pooled.end(), absr[v].begin(), absr[v].end());
    pooled_round += round[v] * static_cast<double>(absr[v].size());
  }
  fit.noise_gray = noise_of(pooled, pooled.empty() ? 0.0 : pooled_round / static_cast<double>(pooled.size()));
  fit.netd = fit.noise_gray / fit.gain;
  for (size_t v = 0; v < V; ++v) {
    ViewFit& vf = fit.views[v];
    const Sensor& sensor = cat.sensors[cat.sensor_index(vf.name)];
    vf.own_raw = vf.raw_w != fit.raw_w || vf.raw_h != fit.raw_h || sensor.raw.has_value();
    vf.own_netd = !vf.noise_agrees || sensor.netd.has_value();
  }
}

}  // namespace

double aperture_for_fwhm(const Catalogue& cat, int width, double fwhm_pixels) {
  // reference::psf_fwhm_pixels is inversely proportional to the aperture.
  Catalogue one = cat;
  one.physics.aperture_m = 1.0;
  Sensor view;
  view.width = width;
  return reference::psf_fwhm_pixels(one, view) / fwhm_pixels;
}

CameraFit fit_camera(const Captures& captures, const Catalogue& cat, const AssetSet& assets,
                     const ModelSettings& model) {
  check_captures(captures);
  CameraFit fit;
  fit_view_grids(captures, cat, fit);
  const Problem p = fit_problem(captures, cat, assets, model, fit);
  const Evaluation e = fit_blur(p, captures.views[0].width, fit);
  fit.aperture_m = aperture_for_fwhm(cat, captures.views[0].width, fit.fwhm_pixels);
  const double offset = fit_window(e, model, fit);
  fit_noise(captures, cat, e, offset, fit);
  fit.subject = e.subject;
  fit.cells = static_cast<int>(e.pairs);
  return fit;
}

Catalogue fitted_catalogue(const Catalogue& cat, const CameraFit& fit) {
  Catalogue out = cat;
  out.physics.aperture_m = fit.aperture_m;
  for (size_t v = 0; v < fit.views.size(); ++v) {
    const int s = out.sensor_index(fit.views[v].name);
    if (s < 0) throw InputError(cat.source + ": the catalogue has no camera view \"" + fit.views[v].name + "\"");
    Sensor& sensor = out.sensors[s];
    sensor.raw = fit.views[v].own_raw ? std::optional(fit.view_raw(v)) : std::nullopt;
    sensor.netd = fit.views[v].own_netd ? std::optional(fit.view_netd(v)) : std::nullopt;
  }
  return out;
}

ModelSettings fitted_model(const ModelSettings& model, const CameraFit& fit) {
  ModelSettings m = model;
  m.model = Model::physics;
  m.netd = fit.netd;
  m.raw_width = fit.raw_w;
  m.raw_height = fit.raw_h;
  m.raw_grids.clear();  // the fitted grid, not a list drawn from
  // The camera the fit assumes: one frame, the fitted fixed window, bilinear, unsmoothed.
  m.frames = 1;
  m.window_auto = false;
  m.window_lo = fit.display_min;
  m.window_hi = fit.display_max;
  m.display_filter = DisplayFilter::bilinear;
  m.smooth = 0;
  return m;
}

std::string not_camera_like(const Captures& captures, const CameraFit& fit) {
  const auto g = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return std::string(text);
  };
  // "the X view", "the X and Y views": where only some views are at fault.
  const auto of_views = [&](const std::vector<size_t>& vs) {
    std::vector<std::string> names;
    for (size_t v : vs) names.push_back(fit.views[v].name);
    return " of the " + spoken_list(names) + (vs.size() == 1 ? " view" : " views");
  };
  std::vector<size_t> full, quiet;
  double loudest = 0;
  for (size_t v = 0; v < fit.views.size() && v < captures.views.size(); ++v) {
    const ViewFit& vf = fit.views[v];
    if (vf.raw_w == captures.views[v].width && vf.raw_h == captures.views[v].height) full.push_back(v);
    if (fit.view_noise_gray(v) < kMinCameraNoiseGray) {
      quiet.push_back(v);
      loudest = std::max(loudest, fit.view_noise_gray(v));
    }
  }
  std::string why;
  const auto add = [&](const std::string& w) { why += (why.empty() ? "" : ", and ") + w; };
  if (!full.empty()) {
    const ViewFit& vf = fit.views[full.front()];
    add("the fitted raw grid" + (full.size() == fit.views.size() ? std::string() : of_views(full)) + ", " +
        std::to_string(vf.raw_w) + "x" + std::to_string(vf.raw_h) +
        ", is the view's own size (no coarser grid reproduces the images)");
  }
  if (!quiet.empty())
    add("the noise" + (quiet.size() == fit.views.size() ? std::string() : of_views(quiet)) + ", " + g(loudest) +
        " gray levels per raw pixel, is under " + g(kMinCameraNoiseGray) + " of a gray level");
  return why;
}

}  // namespace portalsim::calibrate
