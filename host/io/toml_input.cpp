#include "io/toml_input.h"

#include <algorithm>
#include <vector>

#include "base/error.h"
#include "io/input_file.h"

namespace portalsim::io {

namespace {

// Walks the text as TOML's lexer would (strings, comments, table headers) and counts
// nesting: [ and { inside values, plus each part of a dotted key or table header
// (a.b.c = 1 nests tables too, and toml++ recurses on those as well).
void check_depth(std::string_view s, const std::string& source) {
  int depth = 0, header_levels = 0, key_levels = 0;
  std::string open;           // the brackets open in the current value, innermost last
  bool in_key = true;         // reading a key: at a line's start, or after { or , in an inline table
  bool line_has_key = false;  // a '[' before any key on a line at depth 0 opens a header
  size_t line = 1, line_start = 0;
  const auto fail = [&](size_t at) {
    throw InputError(where(source, line, at - line_start + 1) + ": arrays and tables nested deeper than " +
                     std::to_string(kMaxTomlDepth) + " levels");
  };
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    const auto starts = [&](std::string_view t) { return s.substr(i, t.size()) == t; };
    if (c == '\n') {
      ++line, line_start = i + 1, line_has_key = false;
      if (depth == 0) in_key = true, key_levels = 0;
    } else if (c == '#') {
      while (i + 1 < s.size() && s[i + 1] != '\n') ++i;
    } else if (starts("\"\"\"") || starts("\'\'\'")) {
      const std::string_view q = s.substr(i, 3);
      i += 3;
      while (i < s.size() && !starts(q)) {
        if (s[i] == '\\' && q[0] == '"')
          ++i;
        else if (s[i] == '\n')
          ++line, line_start = i + 1;
        ++i;
      }
      while (i + 1 < s.size() && s[i + 1] == q[0]) ++i;  // i on the string's last quote
      line_has_key = true;
    } else if (c == '"' || c == '\'') {
      for (++i; i < s.size() && s[i] != c && s[i] != '\n'; ++i)
        if (s[i] == '\\' && c == '"') ++i;
      line_has_key = true;
    } else if (c == '[' && depth == 0 && !line_has_key) {  // a [table] or [[array]] header
      header_levels = 1;
      for (; i + 1 < s.size() && s[i + 1] != '\n' && s[i + 1] != '#'; ++i)
        if (s[i + 1] == '.' && ++header_levels > kMaxTomlDepth) fail(i + 1);
    } else if (c == '[' || c == '{') {
      open.push_back(c);
      if (++depth + header_levels + key_levels > kMaxTomlDepth) fail(i);
      in_key = c == '{', key_levels = 0;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
      open.pop_back();
    } else if (c == ',' && !open.empty() && open.back() == '{') {
      in_key = true, key_levels = 0;
    } else if (c == '=' && in_key) {
      in_key = false;
      line_has_key = true;
    } else if (c == '.' && in_key) {
      if (depth + header_levels + ++key_levels > kMaxTomlDepth) fail(i);
      line_has_key = true;
    } else if (c != ' ' && c != '\t' && c != '\r') {
      line_has_key = true;
    }
  }
}

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

toml::table parse_toml(std::string_view text, const std::string& source) {
  text = check_text(text, source, Bom::refuse);
  check_depth(text, source);
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(where(source, e.source().begin.line, e.source().begin.column) +
                     ": syntax: " + std::string(e.description()));
  }
}

void reject_unknown_keys(const toml::table& t, std::initializer_list<std::string_view> known, const std::string& source,
                         const std::string& field) {
  reject_unknown_keys(t, std::span<const std::string_view>(known.begin(), known.size()), source, field);
}

void reject_unknown_keys(const toml::table& t, std::span<const std::string_view> known, const std::string& source,
                         const std::string& field) {
  for (const auto& [k, node] : t) {
    const std::string_view key = k.str();
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string_view best;
    size_t best_d = 3;  // suggest only near misses
    for (std::string_view n : known)
      if (const size_t d = edit_distance(key, n); d < best_d) best = n, best_d = d;
    std::string msg = where(source, node.source().begin.line, node.source().begin.column) + ": " +
                      (field.empty() ? "" : field + ".") + std::string(key) + ": unknown key";
    if (!best.empty()) msg += " (did you mean " + std::string(best) + "?)";
    throw InputError(msg);
  }
}

}  // namespace portalsim::io
