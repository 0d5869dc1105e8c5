#include "sink/folder_reader.h"

#include <algorithm>
#include <filesystem>
#include <functional>

#include "assets/assets.h"
#include "assets/image_io.h"
#include "base/error.h"
#include "io/input_file.h"
#include "sink/pooling.h"

namespace portalsim {

namespace fs = std::filesystem;

namespace {

std::string find_image(const fs::path& dir, const std::string& stem) {
  for (const char* ext : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".pgm"}) {
    const fs::path p = dir / (stem + ext);
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) return p.string();
  }
  return "";
}

// The one line of a small text file: checked text, one line, trailing blanks dropped.
std::string one_line(std::string_view raw, const std::string& source) {
  std::string line(io::check_text(raw, source, io::Bom::refuse));
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r' || line.back() == ' ')) line.pop_back();
  if (const size_t nl = line.find('\n'); nl != std::string::npos)
    throw InputError(source + ":2: expected one line, found more");
  return line;
}

}  // namespace

std::vector<std::string> find_scenario_folders(const std::vector<std::string>& paths, const Catalogue& cat) {
  // A scenario folder holds the first pooled view's image.
  const std::string& stem = cat.sensors[FeatureLayout::of(cat, 1).pooled.at(0)].name;
  std::vector<std::string> out;
  std::function<void(const fs::path&)> walk = [&](const fs::path& p) {
    if (!find_image(p, stem).empty()) {
      out.push_back(p.string());
      return;
    }
    std::vector<fs::path> subs;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(p, ec))
      if (e.is_directory(ec) && e.path().filename().string()[0] != '.') subs.push_back(e.path());
    std::sort(subs.begin(), subs.end());
    for (const fs::path& s : subs) walk(s);
  };
  for (const std::string& p : paths) {
    std::error_code ec;
    if (!fs::is_directory(p, ec)) throw InputError(p + ": not a folder");
    const size_t before = out.size();
    walk(p);
    if (out.size() == before)
      throw InputError(p + ": no scenario folders (none holds " + stem + ".png or " + stem + ".jpg)");
  }
  return out;
}

bool read_scenario_folder(const std::string& dir, const Catalogue& cat, BatchOutput& out, size_t i) {
  const fs::path d(dir);
  const FeatureLayout& f = out.layout;
  std::vector<Image> views;  // the pooled views, by their sensors' names
  for (int view : f.pooled) {
    const Sensor& s = cat.sensors[view];
    const std::string path = find_image(d, s.name);
    if (path.empty()) throw InputError((d / s.name).string() + ".png: missing");
    views.push_back(to_gray(read_image(path, s.name), false));
    if (views.back().width != s.width || views.back().height != s.height)
      throw InputError(path + ": is " + std::to_string(views.back().width) + "x" + std::to_string(views.back().height) +
                       ", the catalogue's " + s.name + " view is " + std::to_string(s.width) + "x" +
                       std::to_string(s.height));
  }
  pool_images(cat, f, views, out.features.data() + i * f.image_features());
  const fs::path metal = d / "metal.txt";
  const std::vector<uint8_t> zones =
      parse_metal_text(io::read_file(metal.string(), "metal file", io::kMaxTextBytes), metal.string(), cat.zones);
  std::copy(zones.begin(), zones.end(), out.metal.begin() + static_cast<std::ptrdiff_t>(i * zones.size()));
  const fs::path threat = d / "threat.txt";
  return parse_threat_text(io::read_file(threat.string(), "label file", io::kMaxTextBytes), threat.string());
}

std::vector<uint8_t> parse_metal_text(std::string_view text, const std::string& source, int count) {
  // `count` integers 0..200, separated by commas and/or spaces.
  const size_t Z = static_cast<size_t>(count);
  const std::string line = one_line(text, source);
  std::vector<int> zones;
  std::string cur;
  for (char c : line + ",") {
    if (c == ',' || c == ' ' || c == '\t') {
      if (cur.empty()) continue;
      if (cur.size() > 3 || cur.find_first_not_of("0123456789") != std::string::npos)
        throw InputError(source + ":1: zone " + std::to_string(zones.size() + 1) + ": \"" + cur +
                         "\" is not an integer 0..200");
      zones.push_back(std::stoi(cur));
      if (zones.back() > 200)
        throw InputError(source + ":1: zone " + std::to_string(zones.size()) + ": " + cur + " is above 200");
      if (zones.size() > Z) break;
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  if (zones.size() != Z)
    throw InputError(source + ":1: expected " + std::to_string(Z) + " zone values, found " +
                     (zones.size() > Z ? "more" : std::to_string(zones.size())));
  return std::vector<uint8_t>(zones.begin(), zones.end());
}

bool parse_threat_text(std::string_view text, const std::string& source) {
  const std::string raw = one_line(text, source);
  const std::string t = normalise_name(raw);
  if (t == "yes" || t == "positive" || t == "threat" || t == "1") return true;
  if (t == "no" || t == "negative" || t == "0") return false;
  throw InputError(source + ":1: \"" + raw + "\" is not yes or no");
}

}  // namespace portalsim
