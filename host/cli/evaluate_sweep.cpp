#include "cli/evaluate_sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "base/embedded.h"
#include "base/error.h"
#include "cli/python_requests.h"
#include "evaluate/report.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "scene/philox.h"
#include "sink/staging.h"

namespace portalsim {
namespace cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The Latin hypercube's Philox stream (apart from the generator's by value).
constexpr uint32_t kStreamHypercube = 0x4c485344;  // "LHSD"

// One setting: knob key -> value text, in the order the sweep names the knobs.
using Setting = std::vector<std::pair<std::string, std::string>>;

struct Axis {
  std::string key, text;            // "netd", "1,2,3" or "1..4"
  std::vector<std::string> values;  // grid
  double lo = 0, hi = 0;            // hypercube
};

// "netd=1,2,3 mmw_raw=16x16,28x28": each knob once, each known.
std::vector<Axis> parse_axes(const std::string& sweep, bool ranges) {
  std::vector<Axis> axes;
  std::istringstream in(sweep);
  for (std::string item; in >> item;) {
    const size_t eq = item.find('=');
    Axis a;
    a.key = item.substr(0, eq);
    if (eq == std::string::npos || a.key.empty())
      throw InputError("--sweep: \"" + item + "\" is not KNOB=" + (ranges ? "A..B" : "V1,V2,..."));
    a.text = item.substr(eq + 1);
    const Knob* k = find_knob(a.key);
    if (!k) throw InputError("--sweep: \"" + a.key + "\" is not a knob (portalsim knobs lists them)");
    for (const Axis& b : axes)
      if (b.key == a.key) throw InputError("--sweep: knob \"" + a.key + "\" is named twice");
    const std::string where = "--sweep " + a.key;
    if (ranges) {
      if (k->kind != KnobKind::integer && k->kind != KnobKind::number)
        throw InputError(where + ": --samples draws numbers; \"" + a.key +
                         "\" is not a numeric knob (sweep it as a grid, without --samples)");
      const size_t dots = a.text.find("..");
      if (dots == std::string::npos) throw InputError(where + ": \"" + a.text + "\" is not a range A..B");
      const std::string lo = a.text.substr(0, dots), hi = a.text.substr(dots + 2);
      Plan scratch;
      for (const std::string& end : {lo, hi}) set_knob(scratch, *k, end, where);  // each end a value of the knob
      a.lo = std::strtod(lo.c_str(), nullptr);
      a.hi = std::strtod(hi.c_str(), nullptr);
      if (!(a.lo < a.hi))
        throw InputError(where + ": range \"" + a.text + "\" is " + (a.lo == a.hi ? "empty" : "reversed") +
                         "; give A..B with A < B");
    } else {
      std::string v;
      std::istringstream values(a.text);
      while (std::getline(values, v, ',')) {
        if (v.empty()) throw InputError(where + ": an empty value in \"" + a.text + "\"");
        if (std::find(a.values.begin(), a.values.end(), v) != a.values.end())
          throw InputError(where + ": value \"" + v + "\" is listed twice");
        Plan scratch;
        set_knob(scratch, *k, v, where);
        a.values.push_back(v);
      }
      if (a.values.empty()) throw InputError(where + ": no values (give KNOB=V1,V2,...)");
    }
    axes.push_back(a);
  }
  if (axes.empty()) throw InputError("--sweep: no knobs (e.g. \"netd=1,2,3 frames=1,10\")");
  return axes;
}

// Every combination, the first knob slowest.
std::vector<Setting> grid(const std::vector<Axis>& axes) {
  std::vector<Setting> out{{}};
  for (const Axis& a : axes) {
    std::vector<Setting> next;
    for (const Setting& s : out)
      for (const std::string& v : a.values) {
        Setting t = s;
        t.emplace_back(a.key, v);
        next.push_back(t);
      }
    out = next;
  }
  return out;
}

// n settings by Latin hypercube: per knob, the n strata of its range in an order drawn from
// Philox, a uniform draw within each; integer knobs rounded.
std::vector<Setting> hypercube(const std::vector<Axis>& axes, uint64_t n, uint64_t seed) {
  std::vector<Setting> out(n);
  for (uint32_t j = 0; j < axes.size(); ++j) {
    const Axis& a = axes[j];
    std::vector<std::pair<uint32_t, uint64_t>> order;  // (draw, stratum)
    for (uint64_t i = 0; i < n; ++i) order.emplace_back(draw(seed, i, kStreamHypercube, 2 * j)[0], i);
    std::sort(order.begin(), order.end());
    const bool integer = find_knob(a.key)->kind == KnobKind::integer;
    for (uint64_t i = 0; i < n; ++i) {
      const double u =
          (static_cast<double>(order[i].second) + uniform24(draw(seed, i, kStreamHypercube, 2 * j + 1)[0])) /
          static_cast<double>(n);
      double v = a.lo + u * (a.hi - a.lo);
      char text[32];
      if (integer)
        std::snprintf(text, sizeof text, "%.0f", std::round(v));
      else
        std::snprintf(text, sizeof text, "%.4g", v);
      out[i].emplace_back(a.key, text);
    }
  }
  return out;
}

std::string point_name(size_t i) {
  char b[32];
  std::snprintf(b, sizeof b, "point-%04zu", i);
  return b;
}

std::string setting_text(const Setting& s) {
  std::string t;
  for (const auto& [k, v] : s) t += (t.empty() ? "" : " ") + k + "=" + v;
  return t;
}

// sweep.csv: one row per point and entry; sweep.md: Pd at each target Pfa per point.
void write_summary(const fs::path& out, const std::vector<Axis>& axes, const std::vector<Setting>& settings,
                   const std::vector<json>& reports) {
  std::string csv = "point";
  for (const Axis& a : axes) csv += "," + a.key;
  csv += ",entry,auc,auc_lo,auc_hi";
  const json& first = reports[0]["entries"][reports[0]["entry_order"][0].get<std::string>()]["pd_at_pfa"];
  std::vector<std::string> targets;
  for (const json& p : first) {
    targets.push_back(evaluate::number_text(p["pfa_target"].get<double>()));
    csv += ",pd_at_pfa_" + targets.back() + ",pd_lo_" + targets.back() + ",pd_hi_" + targets.back();
  }
  csv += "\n";
  std::string md = "# portalsim evaluate: sweep\n\n" + std::to_string(settings.size()) +
                   " settings; each point's report is in points/ (report.md, report.json, scores.csv, roc.csv).\n\n";
  for (size_t k = 0; k < targets.size(); ++k) {
    md += "## Pd at Pfa " + targets[k] + "\n\n| point |";
    for (const Axis& a : axes) md += " " + a.key + " |";
    for (const json& name : reports[0]["entry_order"]) md += " " + name.get<std::string>() + " |";
    md += "\n|---|";
    for (size_t i = 0; i < axes.size() + reports[0]["entry_order"].size(); ++i) md += "---|";
    md += "\n";
    for (size_t i = 0; i < settings.size(); ++i) {
      md += "| " + point_name(i) + " |";
      for (const auto& kv : settings[i]) md += " " + kv.second + " |";
      for (const json& name : reports[i]["entry_order"]) {
        char b[32];
        std::snprintf(b, sizeof b, " %.1f%% |",
                      100 * reports[i]["entries"][name.get<std::string>()]["pd_at_pfa"][k]["pd"].get<double>());
        md += b;
      }
      md += "\n";
    }
    md += "\n";
  }
  for (size_t i = 0; i < settings.size(); ++i)
    for (const json& name : reports[i]["entry_order"]) {
      const json& e = reports[i]["entries"][name.get<std::string>()];
      csv += point_name(i);
      for (const auto& kv : settings[i]) csv += "," + kv.second;
      csv += "," + name.get<std::string>() + "," + evaluate::number_text(e["auc"].get<double>()) + "," +
             evaluate::number_text(e["auc_interval"][0].get<double>()) + "," +
             evaluate::number_text(e["auc_interval"][1].get<double>());
      for (const json& p : e["pd_at_pfa"])
        csv += "," + evaluate::number_text(p["pd"].get<double>()) + "," +
               evaluate::number_text(p["pd_interval"][0].get<double>()) + "," +
               evaluate::number_text(p["pd_interval"][1].get<double>());
      csv += "\n";
    }
  md += "Every number with its interval: `sweep.csv`. Plots: `sweep.png` (Pd at each target Pfa against each knob).\n";
  write_text_atomic((out / "sweep.csv").string(), csv);
  write_text_atomic((out / "sweep.md").string(), md);
}

}  // namespace

int run_sweep(SpecFlags& flags, const std::string& sweep, const std::string& samples, const std::string& part,
              const std::string& out_text, const EvaluateSettings& settings) {
  if (out_text.empty()) throw InputError("--out: empty folder name");
  if (!samples.empty() && sweep.empty()) throw InputError("--samples: needs --sweep with the ranges (\"netd=1..4\")");
  const bool ranges = !samples.empty();
  uint64_t n = 0;
  if (ranges) {
    n = io::parse_u64(samples, "--samples");
    if (n < 1 || n > 100000) throw InputError("--samples: \"" + samples + "\" is not between 1 and 100000");
  }
  uint64_t part_i = 0, parts = 1;
  if (!part.empty()) {
    const size_t slash = part.find('/');
    if (slash == std::string::npos) throw InputError("--part: \"" + part + "\" is not i/k");
    part_i = io::parse_u64(part.substr(0, slash), "--part");
    parts = io::parse_u64(part.substr(slash + 1), "--part");
    if (parts < 1 || part_i >= parts) throw InputError("--part: \"" + part + "\" needs 0 <= i < k");
  }
  const std::vector<Axis> axes = parse_axes(sweep, ranges);
  const std::vector<Setting> points = ranges ? hypercube(axes, n, settings.options.seed) : grid(axes);
  const RunSpec base = features_spec(build_spec(flags));
  Session s;
  open_catalogue(s, flags.common, &base);
  // Every point's spec checked before anything runs.
  std::vector<RunSpec> specs;
  for (const Setting& p : points) {
    RunSpec spec = base;
    for (const auto& [k, v] : p) {
      spec.origin.erase(k);
      spec.set_knob_text(k, v, "--sweep " + k);
    }
    check_generate(spec, s.catalogue);
    specs.push_back(spec);
  }
  // The sweep's definition: a rerun with the same one resumes, another is refused.
  json def = {{"base_spec", base.to_json()},
              {"sweep", sweep},
              {"samples", n},
              {"classifier", evaluate::classifier_name(settings.options.classifier)},
              {"folds", settings.options.folds},
              {"bootstrap", settings.options.bootstrap},
              {"eval_seed", std::to_string(settings.options.seed)},
              {"pfa", settings.options.pfa}};
  json pts = json::array();
  for (size_t i = 0; i < points.size(); ++i) {
    json p = {{"point", point_name(i)}};
    for (const auto& [k, v] : points[i]) p[k] = v;
    pts.push_back(p);
  }
  def["points"] = pts;
  const std::string def_text = def.dump(2) + "\n";
  const fs::path out(out_text);
  const fs::path def_path = out / "sweep.json";
  std::error_code ec;
  if (fs::exists(def_path, ec)) {
    if (io::read_file(def_path.string(), "sweep definition", io::kMaxTextBytes) != def_text)
      throw OutputError(def_path.string() +
                        ": holds another sweep (its settings, knobs or base spec differ); choose a new --out");
  } else {
    if (fs::exists(out, ec) && (!fs::is_directory(out, ec) || !fs::is_empty(out, ec)))
      throw OutputError(out_text + ": is not an empty folder and holds no sweep.json; choose a new one");
    fs::create_directories(out, ec);
    if (ec) throw OutputError(out_text + ": cannot create the folder: " + ec.message());
    write_text_atomic(def_path.string(), def_text);
  }
  open_backend(s, flags.common);
  EvaluateSettings point_settings = settings;
  point_settings.plot = false;  // the sweep's own plots show the points
  EvaluateTiming timing;
  size_t done = 0, ran = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const fs::path final_dir = out / "points" / point_name(i);
    if (fs::exists(final_dir / "report.json", ec)) {
      ++done;
      continue;
    }
    if (i % parts != part_i) continue;
    // Made under .work/ and renamed into points/ whole: a point is there finished or not at all.
    const fs::path work = out / ".work" / point_name(i);
    fs::remove_all(work, ec);
    fs::create_directories(work / "report", ec);
    if (ec) throw OutputError(work.string() + ": cannot create the folder: " + ec.message());
    std::fprintf(stderr, "evaluate: %s (%zu of %zu): %s\n", point_name(i).c_str(), i + 1, points.size(),
                 setting_text(points[i]).c_str());
    EvaluateTiming t;
    t.generation = generate_data(specs[i], s, (work / "data").string(), settings.options.threads);
    evaluate_folder((work / "data").string(), s, point_settings, (work / "report").string(), t,
                    point_name(i) + " of the sweep (" + setting_text(points[i]) + "; data not kept)");
    fs::create_directories(out / "points", ec);
    fs::rename(work / "report", final_dir, ec);
    if (ec) throw OutputError(final_dir.string() + ": cannot move the finished point there: " + ec.message());
    fs::remove_all(work, ec);
    timing.add(t);
    ++done;
    ++ran;
  }
  fs::remove(out / ".work", ec);  // when empty
  if (done < points.size()) {
    std::printf(
        "%s: %zu of %zu points done (this run: %zu); the rest belong to other parts: run without --part "
        "when they are done to write the table\n",
        out_text.c_str(), done, points.size(), ran);
    if (settings.timing) std::printf("%s\n", timing.line().c_str());
    return 0;
  }
  std::vector<json> reports;
  for (size_t i = 0; i < points.size(); ++i) {
    const std::string path = (out / "points" / point_name(i) / "report.json").string();
    reports.push_back(json::parse(io::read_file(path, "report", io::kMaxTextBytes)));
  }
  write_summary(out, axes, points, reports);
  if (settings.plot) {
    const auto t0 = std::chrono::steady_clock::now();
    // Drawn in a staging folder, then renamed into place.
    StagedFolder staged(out_text);
    run_plot_script(embedded::plot_sweep, staged.dir(), {out_text, staged.dir()}, "sweep.png");
    staged.path("sweep.png");
    staged.commit();
    timing.plots += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  std::printf("%s: %zu points (%zu run now, %zu kept from before): sweep.csv, sweep.md%s\n", out_text.c_str(),
              points.size(), ran, points.size() - ran, settings.plot ? ", sweep.png" : "");
  if (settings.timing) std::printf("%s\n", timing.line().c_str());
  return 0;
}

}  // namespace cli
}  // namespace portalsim
