#include "cli/validate_tables.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>

#include "base/error.h"
#include "base/trim.h"
#include "io/input_file.h"
#include "io/table_fields.h"
#include "sink/feature_rows.h"
#include "sink/h5_file.h"

namespace portalsim::cli {

namespace {

void check_row(const std::string& path, int line, const Table& t, const std::vector<std::string>& f) {
  const std::string where = path + ":" + std::to_string(line);
  if (f.size() != t.names.size())
    throw InputError(where + ": instance has " + std::to_string(f.size()) + " values, the header declares " +
                     std::to_string(t.names.size()) + " attributes");
  for (size_t i = 0; i + 1 < f.size(); ++i) {
    if (f[i] == "?") continue;
    char* end = nullptr;
    std::strtod(f[i].c_str(), &end);
    if (f[i].empty() || *end != '\0')
      throw InputError(where + ": field '" + t.names[i] + "' is \"" + f[i] + "\", not a number");
  }
  if (f.back().empty() || f.back() == "?") throw InputError(where + ": field 'class' is missing");
}

// One data line, checked against the header and kept.
void add_row(Table& t, int line, const std::string& text, io::Quoting quoting) {
  std::vector<std::string> f = io::split_fields(text, quoting, t.path, static_cast<size_t>(line));
  check_row(t.path, line, t, f);
  t.classes.insert(f.back());
  t.rows.push_back(std::move(f));
}

}  // namespace

Table parse_arff(std::istream& in, const std::string& path) {
  Table a;
  a.path = path;
  std::string line;
  bool data = false;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '%') continue;
    const std::string l = lower(t);
    if (!data) {
      if (l.rfind("@attribute", 0) == 0) {
        a.names.push_back(io::arff_attribute(t, path, static_cast<size_t>(n)).name);
        a.name_lines.push_back(n);
      } else if (l.rfind("@data", 0) == 0) {
        data = true;
        if (a.names.size() < 2) throw InputError(path + ": needs at least one attribute and a class");
      }
      continue;
    }
    if (t[0] == '{') throw InputError(path + ":" + std::to_string(n) + ": sparse instances are not supported");
    add_row(a, n, t, io::Quoting::arff);
  }
  if (!data) throw InputError(path + ": no @data section");
  return a;
}

// CSV with a header row; the last column is the class.
Table parse_csv(std::istream& in, const std::string& path) {
  Table a;
  a.path = path;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (!a.names.empty()) {
      add_row(a, n, t, io::Quoting::csv);
      continue;
    }
    a.names = io::split_fields(t, io::Quoting::csv, path, static_cast<size_t>(n));
    a.name_lines.assign(a.names.size(), n);
    if (a.names.size() < 2)
      throw InputError(path + ":" + std::to_string(n) + ": needs at least one attribute and a class");
  }
  if (a.names.empty()) throw InputError(path + ": empty file, no header row");
  return a;
}

// A data.h5 of `generate --format h5`: the "features" columns, the metal zones and the
// label as class. Numbers are written as the ARFF sink writes them, so an h5 run and the
// same run's ARFF give the same table.
Table read_h5_table(const std::string& path) {
  const H5Layout layout = read_h5_layout(path);
  const auto find = [&](const std::string& name, TensorType type, size_t rank) -> const H5Dataset& {
    for (const H5Dataset& d : layout.datasets)
      if (d.name == name) {
        if (d.type != type || d.dims.size() != rank)
          throw InputError(path + ": dataset " + name + " does not have the type and shape generate writes");
        return d;
      }
    throw InputError(path + ": has no \"" + name + "\" dataset" +
                     (name == "features" ? " (write one with generate --what features|both --format h5)" : ""));
  };
  const H5Dataset& features = find("features", TensorType::f32, 1);
  const H5Dataset& metal = find("metal", TensorType::u8, 1);
  const H5Dataset& label = find("label", TensorType::u8, 0);
  if (features.columns.size() != features.dims[0])
    throw InputError(path + ": dataset features: attribute 'columns' names " + std::to_string(features.columns.size()) +
                     " columns, the dataset has " + std::to_string(features.dims[0]));
  std::vector<std::string> classes = {"negative", "positive"};
  for (const H5Attribute& a : layout.attributes)
    if (a.name == "class_names") classes = a.values;
  Table t;
  t.path = path;
  t.names = features.columns;
  for (uint64_t z = 1; z <= metal.dims[0]; ++z) t.names.push_back("zone" + std::to_string(z));
  t.names.push_back("class");
  t.name_lines.assign(t.names.size(), 0);
  const size_t nf = features.dims[0], nz = metal.dims[0];
  const uint64_t block = 4096;
  std::vector<float> f;
  std::vector<uint8_t> m, l;
  for (uint64_t first = 0; first < layout.rows; first += block) {
    const uint64_t n = std::min(block, layout.rows - first);
    f.resize(n * nf);
    m.resize(n * nz);
    l.resize(n);
    read_h5_rows(path, features, first, n, reinterpret_cast<char*>(f.data()));
    read_h5_rows(path, metal, first, n, reinterpret_cast<char*>(m.data()));
    read_h5_rows(path, label, first, n, reinterpret_cast<char*>(l.data()));
    for (uint64_t i = 0; i < n; ++i) {
      std::vector<std::string> row;
      row.reserve(t.names.size());
      for (size_t k = 0; k < nf; ++k) {
        if (!std::isfinite(f[i * nf + k]))
          throw InputError(path + ": dataset features, row " + std::to_string(first + i) + ", column " +
                           features.columns[k] + ": " + std::to_string(f[i * nf + k]) +
                           " is not a number generate writes");
        std::string v;
        append_number(v, f[i * nf + k]);
        row.push_back(std::move(v));
      }
      for (size_t z = 0; z < nz; ++z) row.push_back(std::to_string(m[i * nz + z]));
      if (l[i] >= classes.size())
        throw InputError(path + ": dataset label, row " + std::to_string(first + i) + ": " + std::to_string(l[i]) +
                         " is not an index into attribute class_names");
      row.push_back(classes[l[i]]);
      t.classes.insert(row.back());
      t.rows.push_back(std::move(row));
    }
  }
  return t;
}

namespace {

// A table file opened for reading: a regular file (a FIFO would block, a device never end),
// of any size (tables outgrow the caps of the text formats).
std::ifstream open_table(const std::string& path) {
  io::check_regular_file(path, "feature table", std::numeric_limits<size_t>::max());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  return in;
}

}  // namespace

Table read_arff(const std::string& path) {
  std::ifstream in = open_table(path);
  return parse_arff(in, path);
}

Table read_csv(const std::string& path) {
  std::ifstream in = open_table(path);
  return parse_csv(in, path);
}

namespace {

// "digits" at the end of s[0..end), at least one: returns where they start, or npos.
size_t digits_before(std::string_view s, size_t end) {
  size_t b = end;
  while (b > 0 && s[b - 1] >= '0' && s[b - 1] <= '9') --b;
  return b < end ? b : std::string_view::npos;
}

}  // namespace

bool is_block(std::string_view s) {  // .+_r[0-9]+_c[0-9]+
  const size_t c = digits_before(s, s.size());
  if (c == std::string_view::npos || c < 2 || s.substr(c - 2, 2) != "_c") return false;
  const size_t r = digits_before(s, c - 2);
  return r != std::string_view::npos && r >= 3 && s.substr(r - 2, 2) == "_r";
}

bool is_region(std::string_view s) {  // region[0-9]+
  return s.starts_with("region") && s.size() > 6 && digits_before(s, s.size()) == 6;
}

bool is_zone(std::string_view s) {  // zone[0-9]+
  return s.starts_with("zone") && s.size() > 4 && digits_before(s, s.size()) == 4;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> f;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      f.push_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  f.push_back(trim(cur));
  return f;
}

}  // namespace portalsim::cli
