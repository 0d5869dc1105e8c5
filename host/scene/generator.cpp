#include "scene/generator.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "base/error.h"
#include "io/input_file.h"
#include "scene/philox.h"

namespace portalsim {

namespace {
constexpr uint32_t kMaxAttempts = 4096;  // balanced draws: rejection sampling per index
}

Generator::Generator(const Catalogue& cat, GeneratorSpec spec, uint64_t seed)
    : cat_(cat), spec_(std::move(spec)), seed_(seed) {
  if (spec_.pool.empty())
    for (size_t i = 0; i < cat.objects.size(); ++i) spec_.pool.push_back(static_cast<int>(i));
  if (spec_.subjects.empty())
    for (size_t i = 0; i < cat.subjects.size(); ++i) spec_.subjects.push_back(static_cast<int>(i));
  for (int s : spec_.subjects)
    if (s < 0 || s >= static_cast<int>(cat.subjects.size()))
      throw InputError("subjects: " + std::to_string(s + 1) + " is out of range (1 to " +
                       std::to_string(cat.subjects.size()) + ")");
  if (spec_.min_objects < 0 || spec_.max_objects > kRegions || spec_.min_objects > spec_.max_objects)
    throw InputError("objects: " + std::to_string(spec_.min_objects) + ".." + std::to_string(spec_.max_objects) +
                     " must satisfy 0 <= MIN <= MAX <= 13");
  if (!spec_.rule.empty()) rule_.emplace(cat, spec_.rule, "rule");
  if (spec_.balance) {
    if (!rule_) throw InputError("balance: needs a threat rule (--rule) to know the classes");
    // Both classes must be reachable, or rejection sampling could never finish.
    for (int want : {1, 0}) {
      bool found = false;
      for (uint64_t i = 0; i < 64 && !found; ++i)
        for (uint32_t a = 0; a < kMaxAttempts && !found; ++a) found = (*rule_)(draw_scene(i, a)) == (want == 1);
      if (!found)
        throw InputError("balance: the rule \"" + spec_.rule + "\" is never " + (want ? "true" : "false") +
                         " for scenarios drawn from this pool and object count");
    }
  }
}

Scenario Generator::draw_scene(uint64_t index, uint32_t attempt) const {
  Scenario s;
  // Element layout of the generator stream: attempt * 64 + k.
  const uint32_t e0 = attempt * 64;
  const Philox4 r = draw(seed_, index, kStreamGenerate, e0);
  s.subject = spec_.subjects[below(r[0], static_cast<uint32_t>(spec_.subjects.size()))];
  const int count = spec_.min_objects +
                    static_cast<int>(below(r[1], static_cast<uint32_t>(spec_.max_objects - spec_.min_objects + 1)));
  // Distinct regions by a partial Fisher-Yates shuffle; objects uniform over the pool,
  // variants uniform over the object's drawings.
  std::array<int, kRegions> regions;
  for (int k = 0; k < kRegions; ++k) regions[k] = k;
  for (int k = 0; k < count; ++k) {
    const Philox4 q = draw(seed_, index, kStreamGenerate, e0 + 1 + static_cast<uint32_t>(k));
    const int j = k + static_cast<int>(below(q[0], static_cast<uint32_t>(kRegions - k)));
    std::swap(regions[k], regions[j]);
    const Object& o = cat_.objects[spec_.pool[below(q[1], static_cast<uint32_t>(spec_.pool.size()))]];
    const int v = o.first_variant + static_cast<int>(below(q[2], static_cast<uint32_t>(o.variants.size())));
    s.objects[regions[k]] = static_cast<int16_t>(v);
  }
  return s;
}

Scenario Generator::operator()(uint64_t index) const {
  if (!spec_.balance) {
    Scenario s = draw_scene(index, 0);
    s.label = rule_ && (*rule_)(s) ? 1 : 0;
    return s;
  }
  const bool want = index % 2 == 0;
  for (uint32_t a = 0; a < kMaxAttempts; ++a) {
    Scenario s = draw_scene(index, a);
    if ((*rule_)(s) == want) {
      s.label = want ? 1 : 0;
      return s;
    }
  }
  throw InputError("balance: no " + std::string(want ? "threat" : "non-threat") + " scenario found for index " +
                   std::to_string(index) + " in " + std::to_string(kMaxAttempts) +
                   " draws; the rule is too rare for this pool");
}

std::vector<Scenario> read_scenario_file(const Catalogue& cat, const std::string& path,
                                         std::vector<ListedTransforms>* transforms) {
  const std::string raw = io::read_file(path, "scenario file", io::kMaxTextBytes);
  return parse_scenario_list(cat, raw, path, transforms);
}

std::vector<Scenario> parse_scenario_list(const Catalogue& cat, std::string_view raw, const std::string& path,
                                          std::vector<ListedTransforms>* transforms) {
  // A BOM is allowed: spreadsheets write one. CRLF line ends are too.
  std::istringstream in(std::string(io::check_text(raw, path, io::Bom::skip)));
  std::string line;
  size_t lineno = 0;
  // One line's fields as RFC 4180 reads them: a field may be quoted, with "" for a quote
  // inside; spaces round an unquoted field are dropped. A quote anywhere else, or a quoted
  // field still open at the line's end (no field holds a line break), is refused.
  auto split = [&](const std::string& l) {
    const std::string_view line = std::string_view(l).substr(0, l.size() - (l.ends_with('\r') ? 1 : 0));
    std::vector<std::string> f;
    const auto fail = [&](const std::string& why) {
      throw InputError(path + ":" + std::to_string(lineno) + ": column " + std::to_string(f.size() + 1) + ": " + why);
    };
    const auto blank = [&](size_t k) {
      while (k < line.size() && (line[k] == ' ' || line[k] == '\t')) ++k;
      return k;
    };
    for (size_t at = 0;; ++at) {  // `at`: where the field starts, after the previous comma
      std::string field;
      size_t k = blank(at);
      if (k < line.size() && line[k] == '"') {
        for (++k;; ++k) {
          if (k >= line.size()) fail("a quoted field is not closed on its line");
          if (line[k] == '"' && (k + 1 >= line.size() || line[k + 1] != '"')) break;
          if (line[k] == '"') ++k;  // "" is one quote
          field.push_back(line[k]);
        }
        k = blank(k + 1);
        if (k < line.size() && line[k] != ',') fail("text after the closing quote of a quoted field");
      } else {
        const size_t end = std::min(line.find(',', k), line.size());
        field = std::string(line.substr(k, end - k));
        if (field.find('"') != std::string::npos)
          fail("a quote inside an unquoted field: quote the whole field, and double each quote in it");
        field.erase(field.find_last_not_of(" \t") + 1);
        k = end;
      }
      if (field.size() > kMaxFieldBytes) fail("field longer than " + std::to_string(kMaxFieldBytes) + " bytes");
      f.push_back(std::move(field));
      if (k >= line.size()) return f;
      at = k;
    }
  };
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line[0] != '#') header = split(line);
  }
  if (header.empty()) throw InputError(path + ": empty scenario file (expected a header line)");
  int col_subject = -1, col_label = -1;
  std::array<int, kRegions> col_region;
  col_region.fill(-1);
  // Randomised objects: rotation, scale and flip columns per region.
  const std::array<const char*, 3> kTransformColumns = {"rotation", "scale", "flip"};
  std::array<std::array<int, kRegions>, 3> col_transform;
  for (auto& c : col_transform) c.fill(-1);
  int transform_columns = 0;
  // "region", "rotation", ... followed by 1..13: the region (1-based), 0 for another name,
  // -1 for a number out of range.
  const auto numbered = [](const std::string& h, const std::string& stem) {
    if (h.rfind(stem, 0) != 0 || h.size() <= stem.size() || h.size() > stem.size() + 2 ||
        h.find_first_not_of("0123456789", stem.size()) != std::string::npos)
      return 0;
    const int r = std::stoi(h.substr(stem.size()));
    return r >= 1 && r <= kRegions ? r : -1;
  };
  for (size_t c = 0; c < header.size(); ++c) {
    const std::string h = normalise_name(header[c]);
    for (size_t d = 0; d < c; ++d)
      if (normalise_name(header[d]) == h)
        throw InputError(path + ":" + std::to_string(lineno) + ": column " + std::to_string(c + 1) + " \"" + header[c] +
                         "\": duplicates column " + std::to_string(d + 1));
    if (h == "subject")
      col_subject = static_cast<int>(c);
    else if (h == "label" || h == "class" || h == "threat")
      col_label = static_cast<int>(c);
    else if (int r = numbered(h, "region"); r != 0) {
      if (r < 0)
        throw InputError(path + ":" + std::to_string(lineno) + ": column " + std::to_string(c + 1) + " \"" + header[c] +
                         "\": there are regions 1 to 13 only");
      col_region[r - 1] = static_cast<int>(c);
    } else if (h == "index") {
    } else if (
        int t = 0, tr = 0; [&] {
          for (t = 0; t < 3; ++t)
            if ((tr = numbered(h, kTransformColumns[t])) != 0) return true;
          return false;
        }()) {
      if (tr < 0)
        throw InputError(path + ":" + std::to_string(lineno) + ": column " + std::to_string(c + 1) + " \"" + header[c] +
                         "\": there are regions 1 to 13 only");
      col_transform[t][tr - 1] = static_cast<int>(c);
      ++transform_columns;
    } else {
      throw InputError(path + ":" + std::to_string(lineno) + ": column " + std::to_string(c + 1) + " \"" + header[c] +
                       "\": unknown column (expected subject, region1..region13, label)");
    }
  }
  if (transform_columns != 0 && transform_columns != 3 * kRegions)
    throw InputError(path + ":" + std::to_string(lineno) +
                     ": header: the randomised objects' columns come together: rotation1..13, scale1..13 and "
                     "flip1..13 (found " +
                     std::to_string(transform_columns) + " of 39)");
  if (col_subject < 0) throw InputError(path + ":" + std::to_string(lineno) + ": header: no \"subject\" column");
  for (int r = 0; r < kRegions; ++r)
    if (col_region[r] < 0)
      throw InputError(path + ":" + std::to_string(lineno) + ": header: no \"region" + std::to_string(r + 1) +
                       "\" column");
  std::vector<Scenario> out;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line == "\r" || line[0] == '#') continue;
    const std::vector<std::string> f = split(line);
    const std::string at = path + ":" + std::to_string(lineno);
    if (f.size() != header.size())
      throw InputError(at + ": expected " + std::to_string(header.size()) + " fields, found " +
                       std::to_string(f.size()));
    Scenario s;
    const std::string& subj = f[col_subject];
    int sv = 0;
    if (subj.empty() || subj.size() > 3 || subj.find_first_not_of("0123456789") != std::string::npos ||
        (sv = std::stoi(subj)) < 1 || sv > static_cast<int>(cat.subjects.size()))
      throw InputError(at + ": subject: \"" + subj + "\" is not a subject number (1 to " +
                       std::to_string(cat.subjects.size()) + ")");
    s.subject = sv - 1;
    for (int r = 0; r < kRegions; ++r)
      s.objects[r] = parse_object_token(cat, f[col_region[r]].empty() ? "none" : f[col_region[r]],
                                        at + ": region" + std::to_string(r + 1));
    if (col_label >= 0) {
      const std::string l = normalise_name(f[col_label]);
      if (l == "yes" || l == "positive" || l == "1" || l == "threat")
        s.label = 1;
      else if (l == "no" || l == "negative" || l == "0")
        s.label = 0;
      else
        throw InputError(at + ": label: \"" + f[col_label] + "\" is not yes/no");
    } else {
      s.label = -1;  // the caller's rule decides
    }
    if (transform_columns) {
      ListedTransforms lt{at, {}};
      for (int r = 0; r < kRegions; ++r) {
        const std::array<const std::string*, 3> v = {&f[col_transform[0][r]], &f[col_transform[1][r]],
                                                     &f[col_transform[2][r]]};
        const std::string name = ": region" + std::to_string(r + 1) + " ";
        if (s.objects[r] == kNoObject) {
          for (int t = 0; t < 3; ++t)
            if (!v[t]->empty())
              throw InputError(at + name + kTransformColumns[t] + ": \"" + *v[t] + "\" for an empty region");
          continue;
        }
        double num[2] = {0, 0};
        for (int t = 0; t < 2; ++t) {
          const char* end = v[t]->data() + v[t]->size();
          const auto res = std::from_chars(v[t]->data(), end, num[t]);
          if (v[t]->empty() || res.ec != std::errc() || res.ptr != end || !std::isfinite(num[t]))
            throw InputError(at + name + kTransformColumns[t] + ": \"" + *v[t] + "\" is not a number");
        }
        if (*v[2] != "0" && *v[2] != "1") throw InputError(at + name + "flip: \"" + *v[2] + "\" is not 0 or 1");
        lt.t[r] = ObjectTransform{num[0], num[1], *v[2] == "1"};
      }
      if (transforms) transforms->push_back(lt);
    }
    out.push_back(s);
    if (out.size() > 100000000) throw InputError(path + ": more than 100 million scenarios");
  }
  if (out.empty()) throw InputError(path + ": no scenarios after the header");
  return out;
}

}  // namespace portalsim
