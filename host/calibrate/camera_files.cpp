#include "calibrate/camera_files.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>
#include <sstream>
#include <vector>

#include "base/error.h"
#include "base/trim.h"

namespace portalsim::calibrate {

namespace {

std::string number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// A fixed number of decimals, far finer than the fit.
std::string rounded(double v, int decimals) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(decimals);
  s << v;
  return s.str();
}

}  // namespace

std::string camera_spec(const CameraFit& fit, const ModelSettings& model, const std::string& spec_name,
                        const std::string& catalogue_name) {
  const bool own =
      std::any_of(fit.views.begin(), fit.views.end(), [](const ViewFit& v) { return v.own_raw || v.own_netd; });
  std::ostringstream t;
  t << "# The camera fitted by portalsim calibrate. Use it as\n"
    << "#   portalsim generate --spec " << spec_name << " --catalogue " << catalogue_name
    << " --what images --out DIR\n"
    << "# (the catalogue holds the fitted aperture" << (own ? ", and the views' own cameras" : "") << ").\n"
    << "model = \"physics\"\n"
    << "netd = " << rounded(fit.netd, 4) << "            # K rms per raw pixel: " << rounded(fit.noise_gray, 3)
    << " gray levels through the window\n"
    << "mmw_raw = \"" << fit.raw_w << "x" << fit.raw_h << "\"\n"
    << "illumination = " << number(model.illumination) << "    # K, assumed by the fit (the catalogue's room)\n";
  // The fitted window, and the camera's processing the fit assumes, written out whatever
  // the defaults: one frame, a fixed window, bilinear display and no smoothing.
  t << "window = \"" << rounded(fit.display_min, 3) << ".." << rounded(fit.display_max, 3)
    << "\"  # K shown as gray 0 and 255\n"
    << "frames = 1\n"
    << "display_filter = \"bilinear\"\n"
    << "smooth = 0\n";
  return t.str();
}

namespace {

// `[w, h]`.
std::string toml_pair(const std::array<int, 2>& v) {
  std::ostringstream s;
  s << '[' << v[0] << ", " << v[1] << ']';
  return s.str();
}

// A table header, `[name]` or `[[name]]` (a comment after it allowed), and not a row of a
// multi-line array such as `[0, 0, 1],`.
bool is_header(const std::string& t) {
  const std::string h = trim(t.substr(0, t.find('#')));
  if (h.size() < 3 || h.front() != '[' || h.back() != ']') return false;
  const size_t depth = h[1] == '[' ? 2 : 1;
  const std::string inner = trim(h.substr(depth, h.size() - 2 * depth));
  if (inner.empty() || !(std::isalpha(static_cast<unsigned char>(inner[0])) || inner[0] == '_' || inner[0] == '"'))
    return false;
  return inner.find_first_of(",[]") == std::string::npos;
}

// Whether trimmed line `t` sets `key` (`key = ...`).
bool sets(const std::string& t, const std::string& key) {
  return t.rfind(key, 0) == 0 && trim(t.substr(key.size())).rfind('=', 0) == 0;
}

// The quoted string `name = "..."` (or '...') sets, or "" where it is not one.
std::string quoted_value(const std::string& t) {
  const size_t eq = t.find('=');
  const std::string v = trim(t.substr(eq + 1));
  if (v.empty() || (v[0] != '"' && v[0] != '\'')) return "";
  const size_t end = v.find(v[0], 1);
  return end == std::string::npos ? "" : v.substr(1, end - 1);
}

// How many more '[' than ']' a line's value has (before its comment): a multi-line array
// continues while this stays above zero.
int open_brackets(const std::string& line) {
  const std::string v = line.substr(0, line.find('#'));
  return static_cast<int>(std::count(v.begin(), v.end(), '[') - std::count(v.begin(), v.end(), ']'));
}

// The catalogue's lines, each replaceable by any number of lines (none: removed).
struct Edit {
  std::vector<std::string> lines;
  std::vector<std::vector<std::string>> out;
  // Lines [begin, end) of the table whose header is line begin - 1.
  struct Table {
    std::string header;
    size_t begin, end;
  };
  std::vector<Table> tables;

  explicit Edit(const std::string& text) {
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) lines.push_back(line);
    for (const std::string& l : lines) out.push_back({l});
    tables.push_back({"", 0, lines.size()});
    for (size_t i = 0; i < lines.size(); ++i)
      if (is_header(trim(lines[i]))) {
        tables.back().end = i;
        tables.push_back({trim(trim(lines[i]).substr(0, trim(lines[i]).find('#'))), i + 1, lines.size()});
      }
  }

  // Sets `key` in table `t` to `value` (the text after `key = `), replacing its line (and a
  // multi-line value's continuation), or adding it after the table's last line that is not
  // blank or a comment; with no value, removes the key.
  void set(const Table& t, const std::string& key, const std::optional<std::string>& value) {
    for (size_t i = t.begin; i < t.end; ++i)
      if (sets(trim(lines[i]), key)) {
        out[i] = value ? std::vector<std::string>{key + " = " + *value} : std::vector<std::string>{};
        for (int depth = open_brackets(lines[i]); depth > 0 && i + 1 < t.end; depth += open_brackets(lines[i]))
          out[++i].clear();
        return;
      }
    if (!value) return;
    size_t last = t.begin - 1;  // the header itself where the table has no key yet
    for (size_t i = t.begin; i < t.end; ++i) {
      const std::string l = trim(lines[i]);
      if (!l.empty() && l[0] != '#') last = i;
    }
    out[last].push_back(key + " = " + *value);
  }

  std::string text() const {
    std::string s;
    for (const auto& o : out)
      for (const std::string& l : o) s += l + "\n";
    return s;
  }
};

}  // namespace

std::string camera_catalogue(const std::string& catalogue_text, const CameraFit& fit, const std::string& source) {
  Edit e(catalogue_text);
  const std::string aperture =
      number(fit.aperture_m) + "  # PSF FWHM " + rounded(fit.fwhm_pixels, 2) + " view pixels (fitted by calibrate)";
  const auto physics =
      std::find_if(e.tables.begin(), e.tables.end(), [](const Edit::Table& t) { return t.header == "[physics]"; });
  if (physics != e.tables.end()) e.set(*physics, "aperture_m", aperture);
  // Each fitted view's entry: its own raw grid and NETD where the fit gives it them, and
  // neither where it follows the run's camera.
  std::vector<bool> found(fit.views.size(), false);
  for (const Edit::Table& t : e.tables) {
    if (t.header != "[[views]]") continue;
    std::string name;
    for (size_t i = t.begin; i < t.end && name.empty(); ++i)
      if (sets(trim(e.lines[i]), "name")) name = quoted_value(trim(e.lines[i]));
    for (size_t v = 0; v < fit.views.size(); ++v) {
      if (fit.views[v].name != name) continue;
      found[v] = true;
      const ViewFit& vf = fit.views[v];
      const std::array<int, 2> raw = fit.view_raw(v);
      e.set(t, "raw",
            vf.own_raw ? std::optional(toml_pair(raw) + "  # this view's own raw grid (fitted by calibrate)")
                       : std::nullopt);
      e.set(t, "netd",
            vf.own_netd ? std::optional(rounded(fit.view_netd(v), 4) +
                                        "  # K rms per raw pixel: " + rounded(fit.view_netd(v) * fit.gain, 3) +
                                        " gray levels, this view's own (fitted by calibrate)")
                        : std::nullopt);
    }
  }
  for (size_t v = 0; v < fit.views.size(); ++v)
    if (!found[v] && (fit.views[v].own_raw || fit.views[v].own_netd))
      throw InputError(source + ": no [[views]] entry with name = \"" + fit.views[v].name +
                       "\" found in its text, so its fitted raw grid and NETD cannot be written");
  std::string out = e.text();
  if (physics == e.tables.end()) out += "\n[physics]\naperture_m = " + aperture + "\n";
  return out;
}

}  // namespace portalsim::calibrate
