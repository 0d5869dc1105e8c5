#include "cli/evaluate_data.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "base/error.h"
#include "cli/validate_tables.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "scene/scenario_list.h"
#include "schedule/run_state.h"

namespace portalsim::cli {

namespace fs = std::filesystem;

namespace {

// The feature table of a generate folder: the first of these it holds.
std::string find_table(const std::string& dir) {
  for (const char* name : {"features.csv", "features.arff", "data.h5"}) {
    const fs::path p = fs::path(dir) / name;
    std::error_code ec;
    if (fs::exists(p, ec)) return p.string();
  }
  std::error_code ec;
  if (fs::exists(fs::path(dir) / "features.npy", ec))
    throw InputError(dir +
                     ": holds features.npy only; evaluate reads features.csv, features.arff or data.h5 "
                     "(generate --format csv, arff or h5)");
  throw InputError(dir +
                   ": no feature table (features.csv, features.arff or data.h5 with features): make one with "
                   "portalsim generate --what features");
}

// The table as evaluate reads it: the names (the class last), where each is declared, and
// per row its numbers (NaN for "?") and its label.
struct Numbers {
  std::string path;
  std::vector<std::string> names;
  std::vector<int> name_lines;
  std::vector<float> x;  // rows x (names - 1)
  std::vector<uint8_t> label;
};

// A CSV as generate writes it (a header row, then per row numbers or "?" and the class,
// nothing quoted, no blanks, no empty lines), parsed without making a string of each field:
// the numbers are std::from_chars's, as near as strtof's. Anything else (or a number out of
// float's range) returns false, and the general reader (cli/validate_tables.h) takes the
// file, with its messages for bad input.
bool read_plain_csv(const std::string& path, Numbers& out) {
  io::check_regular_file(path, "feature table", std::numeric_limits<size_t>::max());
  const std::string text = io::read_file(path, "feature table", std::numeric_limits<size_t>::max());
  const size_t header_end = text.find('\n');
  if (header_end == std::string::npos) return false;
  const std::string_view header(text.data(), header_end);
  if (header.empty() || header.find_first_of(" \t\r\"'") != std::string_view::npos) return false;
  for (size_t at = 0;;) {
    const size_t comma = std::min(header.find(',', at), header.size());
    if (comma == at) return false;
    out.names.emplace_back(header.substr(at, comma - at));
    if (comma == header.size()) break;
    at = comma + 1;
  }
  if (out.names.size() < 2) return false;
  out.path = path;
  out.name_lines.assign(out.names.size(), 1);
  const size_t nf = out.names.size() - 1;
  const char* p = text.data() + header_end + 1;
  const char* const end = text.data() + text.size();
  while (p < end) {
    for (size_t i = 0; i < nf; ++i) {
      if (p + 1 < end && p[0] == '?' && p[1] == ',') {
        out.x.push_back(std::numeric_limits<float>::quiet_NaN());
        p += 2;
        continue;
      }
      float v = 0;
      const auto [q, ec] = std::from_chars(p, end, v);
      if (ec != std::errc() || q == end || *q != ',') return false;
      out.x.push_back(v);
      p = q + 1;
    }
    const char* line_end = std::find(p, end, '\n');
    const std::string_view c(p, static_cast<size_t>(line_end - p));
    if (c != "positive" && c != "negative") return false;
    out.label.push_back(c == "positive" ? 1 : 0);
    p = line_end == end ? end : line_end + 1;
  }
  return true;
}

Numbers read_table(const std::string& path) {
  Numbers out;
  if (path.ends_with(".csv") && read_plain_csv(path, out)) return out;
  out = Numbers();
  const Table t = path.ends_with(".csv")    ? read_csv(path)
                  : path.ends_with(".arff") ? read_arff(path)
                                            : read_h5_table(path);
  out.path = t.path;
  out.names = t.names;
  out.name_lines = t.name_lines;
  const size_t nf = t.names.size() - 1;  // the class is last
  out.label.reserve(t.rows.size());
  out.x.reserve(t.rows.size() * nf);
  size_t line = 0;
  for (const auto& row : t.rows) {
    ++line;
    const std::string& c = row.back();
    if (c != "positive" && c != "negative")
      throw InputError(t.path + ": row " + std::to_string(line) + ": field 'class' is \"" + c +
                       "\", not positive or negative");
    out.label.push_back(c == "positive" ? 1 : 0);
    for (size_t i = 0; i < nf; ++i)
      out.x.push_back(row[i] == "?" ? std::nanf("") : std::strtof(row[i].c_str(), nullptr));
  }
  return out;
}

// The pooled camera view that sees region r (its means are that view's pixels).
const Sensor* view_of_region(const Catalogue& cat, int r) {
  for (const Sensor& s : cat.sensors)
    if (s.pooled && s.sees(r)) return &s;
  return nullptr;
}

// Where the table declares column i, for errors.
std::string where_column(const Numbers& t, size_t i) {
  // Appended piece by piece: g++ 12 warns falsely (-Wrestrict) on "literal" + a temporary here.
  std::string w = t.path;
  if (t.name_lines[i] > 0) w.append(":").append(std::to_string(t.name_lines[i]));
  return w.append(": column '").append(t.names[i]).append("'");
}

}  // namespace

std::array<uint8_t, kMaxRegions> region_threats(const ThreatRule& rule, const Scenario& s, bool threat) {
  std::array<uint8_t, kMaxRegions> out{};
  for (int r = 0; r < kMaxRegions; ++r) {
    if (s.objects[r] == kNoObject) continue;
    Scenario alone, without = s;
    alone.subject = s.subject;
    alone.objects[r] = s.objects[r];
    without.objects[r] = kNoObject;
    out[r] = rule(alone) || (threat && !rule(without)) ? 1 : 0;
  }
  return out;
}

EvaluateData read_evaluate_data(const std::string& dir, const Catalogue& cat) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw InputError(dir + ": no such folder");
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": not a folder (give the folder portalsim generate made)");
  const std::string manifest_path = (fs::path(dir) / "manifest.json").string();
  if (!fs::exists(manifest_path, ec))
    throw InputError(dir + ": no manifest.json: not a finished portalsim generate folder");
  const nlohmann::json manifest =
      parse_manifest(io::read_text_file(manifest_path, "manifest", io::Bom::refuse), manifest_path);
  // Columns and regions are read through the catalogue the data set was made with.
  const std::string made_with = manifest.value("catalogue", nlohmann::json::object()).value("hash", "");
  if (made_with != cat.hash)
    throw InputError(dir + ": made with the catalogue " +
                     manifest.value("catalogue", nlohmann::json::object()).value("source", std::string("?")) +
                     " (hash " + made_with + "), not " + cat.source + " (hash " + cat.hash +
                     "): give that catalogue with --catalogue");
  const std::string table_path = find_table(dir);
  Numbers t = read_table(table_path);

  EvaluateData out;
  evaluate::Dataset& d = out.data;
  d.source = dir;
  const size_t nf = t.names.size() - 1;  // the class is last
  d.x.rows = t.label.size();
  d.x.cols = nf;
  d.columns.assign(t.names.begin(), t.names.end() - 1);
  // Each column's sensor: a camera view's blocks by their prefix, a region mean by the
  // view that sees the region, a metal zone to the metal detector.
  for (size_t i = 0; i < nf; ++i) {
    const std::string& n = t.names[i];
    if (is_block(n)) {
      d.sensor.push_back(n.substr(0, n.rfind("_r")));
    } else if (is_region(n)) {
      const int r = std::atoi(n.c_str() + 6) - 1;
      const Sensor* v = r >= 0 && r < cat.region_count() ? view_of_region(cat, r) : nullptr;
      if (!v) throw InputError(where_column(t, i) + ": no camera view of the catalogue sees this region");
      d.sensor.push_back(v->name);
    } else if (is_zone(n)) {
      d.sensor.push_back("metal");
    } else {
      throw InputError(
          where_column(t, i) +
          ": not a feature portalsim writes (VIEW_rY_cX, regionN, zoneN); evaluate cannot tell its sensor");
    }
  }
  // The labels: the class column, positive (a threat) or negative.
  d.label = std::move(t.label);
  d.x.x = std::move(t.x);

  out.about = {{"source", dir}, {"table", fs::path(table_path).filename().string()}};
  const std::string rule = manifest["spec"].value("rule", "");
  out.about["rule"] = rule;
  if (rule.empty()) {
    out.about["region_labels"] = "none: the data set has no rule, so no region holds a threat by one";
    return out;
  }
  // Per region: does it hold a threat? From scenarios.csv, row for row with the table.
  const std::string list_path = (fs::path(dir) / "scenarios.csv").string();
  const ScenarioListFile list(cat, list_path, manifest["spec"].value("bodies", "") == "per-scenario",
                              drawn_number_keys());
  if (list.size() != d.label.size())
    throw InputError(list_path + ": " + std::to_string(list.size()) + " scenarios, the feature table " + table_path +
                     " has " + std::to_string(d.label.size()) + " rows");
  const ThreatRule threat(cat, rule, manifest_path + ": spec.rule");
  std::vector<Scenario> scenes(list.size());
  list.read(0, scenes.size(), 1, scenes.data(), nullptr);
  // Each pooled view's blocks per row, from its columns' names, and so the block side.
  std::map<std::string, int> blocks_x;
  for (size_t j = 0; j < nf; ++j)
    if (is_block(t.names[j]))
      blocks_x[d.sensor[j]] =
          std::max(blocks_x[d.sensor[j]], 1 + std::atoi(t.names[j].c_str() + t.names[j].rfind("_c") + 2));
  d.regions.resize(cat.regions.size());
  nlohmann::json places = nlohmann::json::array();
  for (int r = 0; r < cat.region_count(); ++r) {
    auto& reg = d.regions[r];
    const Region& region = cat.regions[r];
    reg.name = "region" + std::to_string(r + 1);
    reg.label.resize(scenes.size());
    const Sensor* v = view_of_region(cat, r);
    // Its columns: its mean, its view's blocks that overlap it, and the metal zones.
    for (size_t i = 0; i < nf; ++i) {
      const std::string& n = t.names[i];
      if (n == reg.name || d.sensor[i] == "metal") {
        reg.columns.push_back(i);
      } else if (v && is_block(n) && d.sensor[i] == v->name) {
        int by = 0, bx = 0;
        std::sscanf(n.c_str() + v->name.size(), "_r%d_c%d", &by, &bx);
        const int b = v->width / std::max(1, blocks_x[v->name]);
        const Rect& rc = v->rects[r];
        if (bx * b < rc.x + rc.w && (bx + 1) * b > rc.x && by * b < rc.y + rc.h && (by + 1) * b > rc.y)
          reg.columns.push_back(i);
      }
    }
    places.push_back({{"name", reg.name},
                      {"region", region.name},
                      {"view", v ? v->name : ""},
                      {"rect", v ? nlohmann::json::array({v->rects[r].x, v->rects[r].y, v->rects[r].w, v->rects[r].h})
                                 : nlohmann::json::array()}});
  }
  for (size_t i = 0; i < scenes.size(); ++i) {
    const auto threats = region_threats(threat, scenes[i], d.label[i] != 0);
    for (int r = 0; r < cat.region_count(); ++r) d.regions[r].label[i] = threats[r];
  }
  out.about["region_labels"] = "from scenarios.csv and the rule `" + rule +
                               "`: a region holds a threat when the rule holds for its object alone, or the scenario "
                               "is a threat and is not without that object";
  out.about["region_places"] = places;
  return out;
}

}  // namespace portalsim::cli
