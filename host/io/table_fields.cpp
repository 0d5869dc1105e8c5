#include "io/table_fields.h"

#include <algorithm>

#include "base/error.h"

namespace portalsim::io {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

size_t skip_blanks(std::string_view line, size_t k) {
  while (k < line.size() && is_blank(line[k])) ++k;
  return k;
}

bool is_quote(char c, Quoting quoting) { return c == '"' || (quoting == Quoting::arff && c == '\''); }

// The quoted field that starts at line[k] (its opening quote) into `field`; returns where
// it ends, after the closing quote. `fail` throws.
template <class Fail>
size_t read_quoted(std::string_view line, size_t k, Quoting quoting, std::string& field, const Fail& fail) {
  const char quote = line[k];
  for (++k;; ++k) {
    if (k >= line.size()) fail("a quoted field is not closed on its line");
    if (quoting == Quoting::arff && line[k] == '\\') {  // \ escapes the next character
      if (++k >= line.size()) fail("a quoted field is not closed on its line");
    } else if (line[k] == quote) {
      if (quoting == Quoting::arff || k + 1 >= line.size() || line[k + 1] != quote) return k + 1;
      ++k;  // "" is one quote
    }
    field.push_back(line[k]);
  }
}

}  // namespace

size_t split_fields(std::string_view line, std::vector<std::string>& f, Quoting quoting, const std::string& path,
                    size_t line_number, size_t max_bytes) {
  size_t count = 0;
  const auto fail = [&](const std::string& why) {
    throw InputError(path + ":" + std::to_string(line_number) + ": column " + std::to_string(count + 1) + ": " + why);
  };
  for (size_t at = 0;; ++at) {  // `at`: where the field starts, after the previous comma
    if (f.size() <= count) f.emplace_back();
    std::string& field = f[count];
    field.clear();
    size_t k = skip_blanks(line, at);
    if (k < line.size() && is_quote(line[k], quoting)) {
      k = skip_blanks(line, read_quoted(line, k, quoting, field, fail));
      if (k < line.size() && line[k] != ',') fail("text after the closing quote of a quoted field");
    } else {
      const size_t end = std::min(line.find(',', k), line.size());
      field.assign(line.substr(k, end - k));
      if (std::any_of(field.begin(), field.end(), [&](char c) { return is_quote(c, quoting); }))
        fail(quoting == Quoting::csv
                 ? "a quote inside an unquoted field: quote the whole field, and double each quote in it"
                 : "a quote inside an unquoted field: quote the whole field, and put \\ before each quote in it");
      field.erase(field.find_last_not_of(" \t") + 1);
      k = end;
    }
    if (field.size() > max_bytes) fail("field longer than " + std::to_string(max_bytes) + " bytes");
    ++count;
    if (k >= line.size()) return count;
    at = k;
  }
}

std::vector<std::string> split_fields(std::string_view line, Quoting quoting, const std::string& path,
                                      size_t line_number) {
  std::vector<std::string> f;
  f.resize(split_fields(line, f, quoting, path, line_number));
  return f;
}

ArffAttribute arff_attribute(std::string_view line, const std::string& path, size_t line_number) {
  const auto fail = [&](const std::string& why) {
    throw InputError(path + ":" + std::to_string(line_number) + ": @attribute: " + why);
  };
  constexpr std::string_view keyword = "@attribute";
  size_t k = skip_blanks(line, 0);
  if (line.size() - k < keyword.size() ||
      !std::equal(keyword.begin(), keyword.end(), line.begin() + k,
                  [](char a, char b) { return a == (b >= 'A' && b <= 'Z' ? static_cast<char>(b - 'A' + 'a') : b); }))
    fail("not an @attribute line");
  k = skip_blanks(line, k + keyword.size());
  ArffAttribute a;
  if (k < line.size() && is_quote(line[k], Quoting::arff)) {
    k = read_quoted(line, k, Quoting::arff, a.name, fail);
  } else {
    size_t end = k;
    while (end < line.size() && !is_blank(line[end])) ++end;
    a.name.assign(line.substr(k, end - k));
    k = end;
  }
  if (a.name.empty()) fail("no attribute name");
  k = skip_blanks(line, k);
  a.type.assign(line.substr(k));
  a.type.erase(a.type.find_last_not_of(" \t\r") + 1);
  return a;
}

}  // namespace portalsim::io
