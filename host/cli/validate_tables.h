// The feature tables `portalsim validate` reads: ARFF, CSV with a header row, and the
// data.h5 of `generate --format h5`. Bad input is an InputError naming file, line and field.
#pragma once
#include <istream>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace portalsim::cli {

// A feature table: numeric attributes, then the class (nominal) last.
struct Table {
  std::string path;
  std::vector<std::string> names;  // attribute names, class last
  std::vector<int> name_lines;     // where each is declared (1-based; the header row for CSV)
  std::vector<std::vector<std::string>> rows;
  std::set<std::string> classes;
};

// The tables from text; `path` names them in errors.
Table parse_arff(std::istream& in, const std::string& path);
Table parse_csv(std::istream& in, const std::string& path);
// The files: regular files only (a FIFO or a device is refused without blocking).
Table read_arff(const std::string& path);
Table read_csv(const std::string& path);
Table read_h5_table(const std::string& path);

// The kinds of feature column portalsim writes (plan's FeatureLayout::names): a camera
// view's block means (VIEW_rY_cX), the region means (regionN; the thesis's two feature sets,
// tables 6.1/6.3/6.5 and 6.2/6.4/6.6) and the metal zones (zoneN).
bool is_block(std::string_view s);
bool is_region(std::string_view s);
bool is_zone(std::string_view s);

// Lower case (ASCII), and comma-separated items with blanks trimmed (validate's option
// lists; the tables' fields go through io/table_fields.h).
std::string lower(std::string s);
std::vector<std::string> split_commas(const std::string& line);

}  // namespace portalsim::cli
