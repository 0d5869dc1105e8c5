#include "evaluate/metal_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "backend/opencl/metal_map.h"
#include "backend/reference/stages.h"
#include "base/error.h"
#include "base/parallel.h"
#include "scene/philox.h"

namespace portalsim::evaluate {

namespace {

using nlohmann::json;

constexpr std::array<const char*, 3> kAxisNames{"x", "y", "z"};
constexpr std::array<std::array<double, 3>, 3> kAxes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
// Most samples one walk may take, and most probes (walks x samples) one map may hold.
constexpr size_t kMaxSamples = 100000, kMaxProbes = size_t{1} << 24;  // about 3 GB of responses

struct Grid {
  std::vector<double> x, z;  // cell centres, metres
  size_t cells() const { return x.size() * z.size(); }
};

// Cells across the passage, symmetric about its middle, and up from the floor to body_height.
Grid grid_of(const MetalPhysics& mp, double step) {
  Grid g;
  const int nx = static_cast<int>(std::floor(mp.panel_separation / step + 1e-9));
  const int nz = static_cast<int>(std::floor(mp.body_height / step + 1e-9));
  for (int i = 0; i < nx; ++i) g.x.push_back((i - (nx - 1) / 2.0) * step);
  for (int j = 0; j < nz; ++j) g.z.push_back((j + 0.5) * step);
  return g;
}

size_t samples_of(const MetalMapSettings& s) {
  return static_cast<size_t>(std::floor(2 * s.walk * s.sample_rate / s.speed + 1e-9)) + 1;
}

// The test object: its catalogue entry (first drawing) and length, the drawing's longer side.
struct TestObject {
  int object = -1, variant = -1;
  double length = 0;
};
TestObject test_object(const Catalogue& cat, const std::string& name) {
  TestObject t;
  t.object = cat.find_object(name);
  if (t.object < 0) return t;
  t.variant = cat.objects[t.object].first_variant;
  const std::array<double, 2> side = cat.long_side(t.variant);
  t.length = std::max(side[0], side[1]);
  return t;
}

// Whether the object, centred at (x, z) with its long side along `axis`, fits between the
// panels and above the floor.
bool reachable(const MetalPhysics& mp, double length, const std::array<double, 3>& axis, double x, double z) {
  return std::fabs(x) + std::fabs(axis[0]) * length / 2 < mp.panel_separation / 2 &&
         z - std::fabs(axis[2]) * length / 2 >= 0;
}

// The benign items of kBenignItems the catalogue has (object indices), and the names it lacks.
std::vector<int> benign_present(const Catalogue& cat, std::vector<std::string>* missing) {
  std::vector<int> out;
  for (const char* name : kBenignItems) {
    const int o = cat.find_object(name);
    if (o >= 0 && cat.objects[o].metal != 0 && std::find(out.begin(), out.end(), o) == out.end())
      out.push_back(o);
    else if (o < 0 && missing)
      missing->push_back(name);
  }
  return out;
}

void add_object(std::vector<double>& objects, const std::array<double, 9>& tensor, double lx, double ly, double lz) {
  std::array<double, PS_MV_LEN> rec{};
  std::copy(tensor.begin(), tensor.end(), rec.begin());
  rec[PS_MV_LONG_X] = lx;
  rec[PS_MV_LONG_Y] = ly;
  rec[PS_MV_LONG_Z] = lz;
  objects.insert(objects.end(), rec.begin(), rec.end());
}

void add_walk(MetalWalks& w, const MetalMapSettings& s, double x, double z, int object) {
  for (size_t t = 0; t < w.samples; ++t) {
    // Symmetric about the coils' plane: a sample at y = 0 where the count is odd.
    const double y = (static_cast<double>(t) - static_cast<double>(w.samples - 1) / 2.0) * s.speed / s.sample_rate;
    w.probes.insert(w.probes.end(), {x, y, z, static_cast<double>(object)});
  }
  ++w.walks;
}

// Each zone's response and deduction at every probe, from the kernels or the reference.
opencl::MetalResponses responses(const Catalogue& cat, const MetalWalks& w, OpenCLRuntime* rt) {
  if (rt) return opencl::metal_responses(*rt, cat, w.objects, w.probes);
  const size_t n = w.probes.size() / PS_MP_LEN;
  opencl::MetalResponses out;
  const size_t Z = static_cast<size_t>(cat.zones);
  out.response.resize(n * Z);
  out.deduction.resize(n * Z);
  parallel_for(n, default_threads(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const double* p = &w.probes[i * PS_MP_LEN];
      const double* r = &w.objects[static_cast<size_t>(p[PS_MP_OBJECT]) * PS_MV_LEN];
      reference::MetalObject o{};
      std::copy(r, r + 9, o.tensor.begin());
      o.x = p[PS_MP_X];
      o.y = p[PS_MP_Y];
      o.z = p[PS_MP_Z];
      o.lx = r[PS_MV_LONG_X];
      o.ly = r[PS_MV_LONG_Y];
      o.lz = r[PS_MV_LONG_Z];
      reference::metal_response(cat.metal_physics, o, &out.response[i * Z], &out.deduction[i * Z]);
    }
  });
  return out;
}

// One walk's lowest reading (any zone, any sample) on each pass: base - deduction plus the
// detector's triangular noise where the deduction is not 0 (the physics model's rule), clamped
// to 1..200. Only readings that can be the lowest draw their noise: one whose noise-free value
// less the noise's half-width is above the lowest noise-free value plus it cannot be.
std::vector<uint8_t> lowest_readings(const uint8_t* deduction, size_t samples, const std::vector<int>& base,
                                     const MetalMapSettings& s, uint64_t walk) {
  const int n = s.metal_noise, Z = static_cast<int>(base.size());
  int bound = std::numeric_limits<int>::max();
  for (size_t t = 0; t < samples; ++t)
    for (int z = 0; z < Z; ++z) {
      const int d = deduction[t * Z + z];
      bound = std::min(bound, base[z] - d + (d > 0 ? n : 0));
    }
  struct Candidate {
    uint32_t t, z;
    int value;
    bool noisy;
  };
  std::vector<Candidate> candidates;
  for (size_t t = 0; t < samples; ++t)
    for (int z = 0; z < Z; ++z) {
      const int d = deduction[t * Z + z];
      const bool noisy = n > 0 && d > 0;
      if (base[z] - d - (noisy ? n : 0) <= bound)
        candidates.push_back({static_cast<uint32_t>(t), static_cast<uint32_t>(z), base[z] - d, noisy});
    }
  std::vector<uint8_t> out(s.passes);
  for (int pass = 0; pass < s.passes; ++pass) {
    int lowest = std::numeric_limits<int>::max();
    const uint64_t first = (walk * static_cast<uint64_t>(s.passes) + static_cast<uint64_t>(pass)) * samples;
    for (const Candidate& c : candidates) {
      int value = c.value;
      if (c.noisy) {
        const Philox4 r = draw(s.seed, first + c.t, PS_STREAM_METAL_MAP, c.z);
        value += static_cast<int>(below(r[0], n + 1)) - static_cast<int>(below(r[1], n + 1));
      }
      lowest = std::min(lowest, value);
    }
    out[pass] = static_cast<uint8_t>(std::clamp(lowest, 1, 200));
  }
  return out;
}

double alarm_rate(const std::vector<uint8_t>& lowest, int level) {
  size_t alarms = 0;
  for (uint8_t v : lowest) alarms += v <= level;
  return lowest.empty() ? 0.0 : static_cast<double>(alarms) / static_cast<double>(lowest.size());
}

// v to `per` parts of a unit (1e9: nanometres), so that 0.35 prints as 0.35.
double rounded(double v, double per) { return std::round(v * per) / per; }

std::string text(double v) {
  char t[32];
  std::snprintf(t, sizeof t, "%g", v);
  return t;
}

}  // namespace

void check_metal_map(const Catalogue& cat, const MetalMapSettings& s) {
  if (!cat.metal_physics.present)
    throw InputError("--metal-map: the catalogue has no [metal.physics] section (the coil model the map needs)");
  if (cat.find_object(s.object) < 0)
    throw InputError("--metal-map: unknown object '" + s.object + "' (the catalogue has " + cat.object_names() + ")");
  auto finite_positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!finite_positive(s.grid_step))
    throw InputError("--grid-step: must be a number of metres above 0, not " + text(s.grid_step));
  if (grid_of(cat.metal_physics, s.grid_step).cells() == 0) {
    char text[160];
    std::snprintf(text, sizeof text, "--grid-step: %g m leaves no cell across the %g m passage or up its %g m",
                  s.grid_step, cat.metal_physics.panel_separation, cat.metal_physics.body_height);
    throw InputError(text);
  }
  if (!finite_positive(s.speed)) throw InputError("--speed: must be above 0 m/s, not " + text(s.speed));
  if (!finite_positive(s.sample_rate))
    throw InputError("--sample-rate: must be above 0 Hz, not " + text(s.sample_rate));
  if (!finite_positive(s.walk)) throw InputError("walk: must be above 0 m");
  if (samples_of(s) > kMaxSamples)
    throw InputError("--sample-rate: " + std::to_string(samples_of(s)) + " samples a walk at this --speed; at most " +
                     std::to_string(kMaxSamples));
  if (s.passes < 1 || s.passes > 100000)
    throw InputError("--passes: must be 1 to 100000, not " + std::to_string(s.passes));
  if (!(s.pfa >= 0 && s.pfa <= 1)) throw InputError("--clean-pfa: must be within 0..1, not " + text(s.pfa));
  if (s.settings.empty()) throw InputError("--sensitivity: give at least one level, 1 to 199");
  for (int v : s.settings)
    if (v < 1 || v > 199) throw InputError("--sensitivity: each level must be 1 to 199, not " + std::to_string(v));
  if (s.metal_noise < 0 || s.metal_noise > 199)
    throw InputError("--metal-noise: must be 0 to 199 counts, not " + std::to_string(s.metal_noise));
  const size_t walks = 3 * grid_of(cat.metal_physics, s.grid_step).cells() +
                       cat.subjects.size() * benign_present(cat, nullptr).size() * cat.regions.size();
  if (walks * samples_of(s) > kMaxProbes)
    throw InputError("--grid-step: " + std::to_string(walks) + " walks of " + std::to_string(samples_of(s)) +
                     " samples exceed the map's " + std::to_string(kMaxProbes) + " places; a coarser grid or rate");
}

MetalWalks metal_map_walks(const Catalogue& cat, const MetalMapSettings& s) {
  const MetalPhysics& mp = cat.metal_physics;
  const Grid g = grid_of(mp, s.grid_step);
  const TestObject t = test_object(cat, s.object);
  MetalWalks w;
  w.samples = samples_of(s);
  for (int a = 0; a < 3; ++a) {
    const std::array<double, 3>& u = kAxes[a];
    add_object(w.objects, cat.polarizability(t.variant, u), u[0] * t.length, u[1] * t.length, u[2] * t.length);
    for (double z : g.z)
      for (double x : g.x) add_walk(w, s, x, z, a);
  }
  // Clean testers: each subject with each benign item in each region, as generate places it
  // (its region's centre where its first view places it, Sensor::place, in the portal's
  // field), drawn as the catalogue has it.
  const double scale = cat.metres_per_field_unit();
  for (size_t subject = 0; subject < cat.subjects.size(); ++subject)
    for (int o : benign_present(cat, nullptr)) {
      const int v = cat.objects[o].first_variant;
      const std::array<double, 2> side = cat.long_side(v);
      const int record = static_cast<int>(w.objects.size() / PS_MV_LEN);
      add_object(w.objects, cat.polarizability(v), side[0], 0.0, side[1]);
      for (int r = 0; r < cat.region_count(); ++r) {
        const int k = first_view(cat.sensors, r);
        if (k < 0) throw InputError("--metal-map: region " + cat.regions[r].name + " is in no view");
        const Sensor& sensor = cat.sensors[k];
        const Rect rc = sensor.place(static_cast<int>(subject), r);
        const double col = sensor.field_col(rc.x + rc.w / 2.0), row = sensor.field_row(rc.y + rc.h / 2.0);
        add_walk(w, s, (col - kFieldWidth / 2.0) * scale, mp.body_height - row * scale, record);
      }
    }
  return w;
}

namespace {

double clean_rate(const std::vector<std::vector<uint8_t>>& clean, int level) {
  double sum = 0;
  for (const auto& v : clean) sum += alarm_rate(v, level);
  return sum / static_cast<double>(clean.size());
}

// What was mapped and how: the object, its carrier, the grid, the coils, the walk and the alarm rule.
void describe_map(json& report, const Catalogue& cat, const MetalMapSettings& s, const TestObject& t, const Grid& g,
                  const MetalWalks& w) {
  const MetalPhysics& mp = cat.metal_physics;
  const Object& object = cat.objects[t.object];
  report["object"] = object.name;
  report["metal_category"] = cat.metal_categories[object.metal];
  report["polarizability_cm3"] = mp.polarizability.empty() ? 0.0 : mp.polarizability[object.metal];
  report["anisotropy"] = object.metal_anisotropy;
  report["length_m"] = rounded(t.length, 1e6);
  report["standards"] = "NIJ 0601.02, ASTM F1468, ASTM F3566-22 (simplified: docs/model/metal.md)";
  report["carrier"] = cat.subjects[0].name;
  report["grid"] = {{"step_m", s.grid_step},
                    {"panel_separation_m", mp.panel_separation},
                    {"body_height_m", mp.body_height},
                    {"x_m", json::array()},
                    {"z_m", json::array()}};
  report["coils"] = {{"panel_a_x_m", -mp.panel_separation / 2},
                     {"panel_b_x_m", mp.panel_separation / 2},
                     {"tx_height_m", mp.tx_height},
                     {"rx_height_m", mp.rx_height},
                     {"transmit_on_a", "zones 1-9 transmit on panel A and receive on B; zones 10-19 the other way"}};
  for (double x : g.x) report["grid"]["x_m"].push_back(rounded(x, 1e9));
  for (double z : g.z) report["grid"]["z_m"].push_back(rounded(z, 1e9));
  report["walk"] = {{"speed_m_per_s", s.speed},
                    {"sample_rate_hz", s.sample_rate},
                    {"from_y_m", -static_cast<double>(w.samples - 1) / 2.0 * s.speed / s.sample_rate},
                    {"samples", w.samples},
                    {"reading", "each zone's lowest reading over the walk (the peak of its time series)"}};
  report["passes"] = s.passes;
  report["metal_noise"] = s.metal_noise;
  report["seed"] = std::to_string(s.seed);
  report["alarm_rule"] =
      "a pass alarms at sensitivity S when any zone's reading, at any sample, is S or below "
      "(200 reads no metal; a higher S is more sensitive)";
}

// The map, per orientation (rows of z, columns of x; null where the object cannot be), and the
// critical orientation.
void map_orientations(json& report, const MetalPhysics& mp, const Grid& g, const TestObject& t, const MetalWalks& w,
                      const opencl::MetalResponses& r, const std::vector<std::vector<uint8_t>>& lowest, int Z,
                      int level) {
  json orientations = json::array();
  double best_mean = 2, all_max = 0, all_min = std::numeric_limits<double>::infinity();
  json critical;
  for (int a = 0; a < 3; ++a) {
    json pd = json::array(), peak = json::array(), deduction = json::array(), zones = json::array();
    double sum = 0, lo = std::numeric_limits<double>::infinity(), hi = 0;
    size_t counted = 0;
    json worst;
    double worst_pd = 2, worst_peak = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < g.z.size(); ++j) {
      json pd_row = json::array(), peak_row = json::array(), ded_row = json::array(), zones_row = json::array();
      for (size_t i = 0; i < g.x.size(); ++i) {
        const size_t walk = a * g.cells() + j * g.x.size() + i;
        if (!reachable(mp, t.length, kAxes[a], g.x[i], g.z[j])) {
          for (json* row : {&pd_row, &peak_row, &ded_row, &zones_row}) row->push_back(nullptr);
          continue;
        }
        std::vector<int> peak_d(Z, 0);
        double peak_r = 0;
        for (size_t k = 0; k < w.samples; ++k)
          for (int z = 0; z < Z; ++z) {
            const size_t at = (walk * w.samples + k) * Z + z;
            peak_d[z] = std::max<int>(peak_d[z], r.deduction[at]);
            peak_r = std::max(peak_r, r.response[at]);
          }
        int alarming = 0;
        for (int z = 0; z < Z; ++z) alarming += level > 0 && 200 - peak_d[z] <= level;
        const double p = alarm_rate(lowest[walk], level);
        pd_row.push_back(p);
        peak_row.push_back(peak_r);
        ded_row.push_back(peak_d);
        zones_row.push_back(alarming);
        sum += p;
        ++counted;
        lo = std::min(lo, peak_r);
        hi = std::max(hi, peak_r);
        if (p < worst_pd || (p == worst_pd && peak_r < worst_peak)) {
          worst_pd = p;
          worst_peak = peak_r;
          worst = {{"x_m", rounded(g.x[i], 1e9)}, {"z_m", rounded(g.z[j], 1e9)}, {"pd", p}, {"peak_response", peak_r}};
        }
      }
      pd.push_back(pd_row);
      peak.push_back(peak_row);
      deduction.push_back(ded_row);
      zones.push_back(zones_row);
    }
    const double mean = counted ? sum / static_cast<double>(counted) : 0.0;
    json o = {{"axis", kAxisNames[a]},
              {"reachable_cells", counted},
              {"mean_pd", mean},
              {"least_sensitive_cell", worst},
              {"peak_response_max", hi},
              {"peak_response_min", counted ? lo : 0.0},
              {"sensitivity_ratio", counted && lo > 0 ? json(hi / lo) : json(nullptr)},
              {"pd", pd},
              {"peak_response", peak},
              {"peak_deduction", deduction},
              {"alarming_zones", zones}};
    orientations.push_back(o);
    if (counted) {
      all_min = std::min(all_min, lo);
      all_max = std::max(all_max, hi);
    }
    // The critical orientation: the lowest mean Pd, then the weakest least-sensitive cell.
    if (counted && (critical.is_null() || mean < best_mean ||
                    (mean == best_mean && worst_peak < critical["position"]["peak_response"].get<double>()))) {
      best_mean = mean;
      critical = {{"orientation", kAxisNames[a]}, {"mean_pd", mean}, {"position", worst}};
    }
  }
  report["orientations"] = orientations;
  report["critical"] = critical;
  report["sensitivity_ratio"] = all_min > 0 && std::isfinite(all_min) ? json(all_max / all_min) : json(nullptr);
}

// Each sensitivity setting (and the operating level): clean false alarms, each benign item's
// nuisance-alarm rate over subjects and regions, and the test object's Pd.
json sensitivity_settings(const Catalogue& cat, const MetalMapSettings& s, const Grid& g, const TestObject& t,
                          const std::vector<int>& benign, const std::vector<std::vector<uint8_t>>& lowest,
                          const std::vector<std::vector<uint8_t>>& clean, int level) {
  const MetalPhysics& mp = cat.metal_physics;
  const int R = cat.region_count();
  const size_t map_walks = 3 * g.cells();
  std::vector<int> levels = s.settings;
  if (level > 0) levels.push_back(level);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  json settings = json::array();
  for (int v : levels) {
    json nuisance = json::object();
    for (size_t b = 0; b < benign.size(); ++b) {
      double sum = 0;
      size_t count = 0;
      for (size_t subject = 0; subject < cat.subjects.size(); ++subject)
        for (int region = 0; region < R; ++region, ++count)
          sum += alarm_rate(lowest[map_walks + (subject * benign.size() + b) * R + region], v);
      nuisance[cat.objects[benign[b]].name] = count ? sum / static_cast<double>(count) : 0.0;
    }
    double pd_sum = 0, pd_min = 1;
    size_t cells = 0;
    json by_axis = json::object();
    for (int a = 0; a < 3; ++a) {
      double axis_sum = 0;
      size_t axis_cells = 0;
      for (size_t j = 0; j < g.z.size(); ++j)
        for (size_t i = 0; i < g.x.size(); ++i) {
          if (!reachable(mp, t.length, kAxes[a], g.x[i], g.z[j])) continue;
          const double p = alarm_rate(lowest[a * g.cells() + j * g.x.size() + i], v);
          axis_sum += p;
          pd_min = std::min(pd_min, p);
          ++axis_cells;
        }
      by_axis[kAxisNames[a]] = axis_cells ? axis_sum / static_cast<double>(axis_cells) : 0.0;
      pd_sum += axis_sum;
      cells += axis_cells;
    }
    settings.push_back({{"sensitivity", v},
                        {"operating", v == level},
                        {"clean_false_alarm_rate", clean_rate(clean, v)},
                        {"nuisance_alarm_rate", nuisance},
                        {"pd_mean", cells ? pd_sum / static_cast<double>(cells) : 0.0},
                        {"pd_mean_by_orientation", by_axis},
                        {"pd_min", cells ? pd_min : 0.0}});
  }
  return settings;
}

}  // namespace

json metal_map(const Catalogue& cat, const MetalMapSettings& s, OpenCLRuntime* rt) {
  check_metal_map(cat, s);
  const MetalPhysics& mp = cat.metal_physics;
  const Grid g = grid_of(mp, s.grid_step);
  const TestObject t = test_object(cat, s.object);
  const MetalWalks w = metal_map_walks(cat, s);
  const opencl::MetalResponses r = responses(cat, w, rt);
  const int Z = cat.zones, R = cat.region_count();

  // Each walk's lowest reading per pass: the test object carried by the first subject, each
  // clean tester on its own body.
  std::vector<std::string> missing;
  const std::vector<int> benign = benign_present(cat, &missing);
  const size_t map_walks = 3 * g.cells();
  auto base_of = [&](size_t walk) -> const std::vector<int>& {
    const size_t subject = walk < map_walks ? 0 : (walk - map_walks) / (benign.size() * R);
    return cat.subjects[subject].base_zones;
  };
  std::vector<std::vector<uint8_t>> lowest(w.walks);
  parallel_for(w.walks, s.threads ? s.threads : default_threads(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k)
      lowest[k] = lowest_readings(&r.deduction[k * w.samples * Z], w.samples, base_of(k), s, k);
  });
  // Clean testers without metal read their bases on every pass (no deduction, so no noise);
  // with benign_clean, the benign items' carriers count as clean too.
  std::vector<std::vector<uint8_t>> clean;
  if (s.benign_clean) clean.assign(lowest.begin() + static_cast<std::ptrdiff_t>(map_walks), lowest.end());
  for (const Subject& subject : cat.subjects)
    clean.emplace_back(s.passes,
                       static_cast<uint8_t>(*std::min_element(subject.base_zones.begin(), subject.base_zones.end())));
  // The operating level: the most sensitive (highest) whose clean false-alarm rate is within Pfa.
  int level = 0;
  for (int v = 199; v >= 1 && level == 0; --v)
    if (clean_rate(clean, v) <= s.pfa) level = v;

  json report;
  describe_map(report, cat, s, t, g, w);
  report["threshold"] = {{"pfa", s.pfa},
                         {"sensitivity", level},
                         {"clean_false_alarm_rate", clean_rate(clean, level)},
                         {"clean_testers", clean.size()},
                         {"clean_testers_are", s.benign_clean ? "each subject without metal, and with each benign "
                                                                "item in each region"
                                                              : "each subject without metal"}};
  report["benign"] = {{"present", json::array()}, {"missing", missing}};
  for (int o : benign) report["benign"]["present"].push_back(cat.objects[o].name);

  map_orientations(report, mp, g, t, w, r, lowest, Z, level);
  report["sensitivity_settings"] = sensitivity_settings(cat, s, g, t, benign, lowest, clean, level);
  return report;
}

std::string metal_map_markdown(const json& j) {
  std::string md;
  char line[512];
  auto num = [](const json& v, const char* fmt) {
    if (v.is_null()) return std::string("-");
    char text[64];
    std::snprintf(text, sizeof text, fmt, v.get<double>());
    return std::string(text);
  };
  md += "# Metal detector sensitivity map: " + j["object"].get<std::string>() + "\n\n";
  std::snprintf(line, sizeof line,
                "The %s (metal category %s, %.4g cm^3, anisotropy %.3g, %.3f m long), carried by %s through the "
                "physics model's portal (%s). Grid step %.3g m; walked at %.3g m/s, read %.4g times a second (%zu "
                "samples from y = %.3g m); %d passes a cell with detector noise %d counts; seed %s.\n\n",
                j["object"].get<std::string>().c_str(), j["metal_category"].get<std::string>().c_str(),
                j["polarizability_cm3"].get<double>(), j["anisotropy"].get<double>(), j["length_m"].get<double>(),
                j["carrier"].get<std::string>().c_str(), j["standards"].get<std::string>().c_str(),
                j["grid"]["step_m"].get<double>(), j["walk"]["speed_m_per_s"].get<double>(),
                j["walk"]["sample_rate_hz"].get<double>(), j["walk"]["samples"].get<size_t>(),
                j["walk"]["from_y_m"].get<double>(), j["passes"].get<int>(), j["metal_noise"].get<int>(),
                j["seed"].get<std::string>().c_str());
  md += line;
  const json& th = j["threshold"];
  std::snprintf(line, sizeof line,
                "**Threshold.** Sensitivity %d: the most sensitive level at which the %zu clean testers (%s) alarm at "
                "most %.4g of passes (they alarm %.4g; 0: no level does). Rule: %s.\n\n",
                th["sensitivity"].get<int>(), th["clean_testers"].get<size_t>(),
                th["clean_testers_are"].get<std::string>().c_str(), th["pfa"].get<double>(),
                th["clean_false_alarm_rate"].get<double>(), j["alarm_rule"].get<std::string>().c_str());
  md += line;
  md += "| orientation | cells | mean Pd | least sensitive cell (x, z m) | its Pd | sensitivity ratio |\n";
  md += "|---|---|---|---|---|---|\n";
  for (const json& o : j["orientations"]) {
    const json& w = o["least_sensitive_cell"];
    std::snprintf(line, sizeof line, "| %s | %zu | %.3f | %s | %s | %s |\n", o["axis"].get<std::string>().c_str(),
                  o["reachable_cells"].get<size_t>(), o["mean_pd"].get<double>(),
                  w.is_null() ? "-" : (num(w["x_m"], "%.3f") + ", " + num(w["z_m"], "%.3f")).c_str(),
                  w.is_null() ? "-" : num(w["pd"], "%.3f").c_str(), num(o["sensitivity_ratio"], "%.4g").c_str());
    md += line;
  }
  const json& c = j["critical"];
  if (!c.is_null()) {
    std::snprintf(line, sizeof line,
                  "\n**Critical orientation** along %s (mean Pd %.3f); **critical position** x = %.3f m, z = %.3f m "
                  "(Pd %.3f). Sensitivity ratio, most to least sensitive cell over all orientations: %s.\n\n",
                  c["orientation"].get<std::string>().c_str(), c["mean_pd"].get<double>(),
                  c["position"]["x_m"].get<double>(), c["position"]["z_m"].get<double>(),
                  c["position"]["pd"].get<double>(), num(j["sensitivity_ratio"], "%.4g").c_str());
    md += line;
  }
  md += "**Sensitivity settings.** Nuisance-alarm rate of each benign item (over subjects and regions):\n\n";
  md += "| sensitivity | clean false alarms | test object mean Pd (x / y / z) | min Pd |";
  for (const json& b : j["benign"]["present"]) md += ' ' + b.get<std::string>() + " |";
  md += "\n|---|---|---|---|";
  for (size_t k = 0; k < j["benign"]["present"].size(); ++k) md += "---|";
  md += "\n";
  for (const json& st : j["sensitivity_settings"]) {
    const json& axis = st["pd_mean_by_orientation"];
    std::snprintf(line, sizeof line, "| %d%s | %.4f | %.3f (%.3f / %.3f / %.3f) | %.3f |", st["sensitivity"].get<int>(),
                  st["operating"].get<bool>() ? " (operating)" : "", st["clean_false_alarm_rate"].get<double>(),
                  st["pd_mean"].get<double>(), axis["x"].get<double>(), axis["y"].get<double>(),
                  axis["z"].get<double>(), st["pd_min"].get<double>());
    md += line;
    for (const json& b : j["benign"]["present"])
      md += ' ' + num(st["nuisance_alarm_rate"][b.get<std::string>()], "%.3f") + " |";
    md += "\n";
  }
  md += "\nStandard benign items the catalogue lacks: ";
  std::string missing;
  for (const json& m : j["benign"]["missing"]) missing += (missing.empty() ? "" : ", ") + m.get<std::string>();
  md += (missing.empty() ? "none" : missing) + ".\n";
  return md;
}

}  // namespace portalsim::evaluate
