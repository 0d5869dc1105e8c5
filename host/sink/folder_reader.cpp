#include "sink/folder_reader.h"

#include <algorithm>
#include <filesystem>
#include <functional>

#include "assets/assets.h"
#include "assets/image_io.h"
#include "base/error.h"
#include "io/input_file.h"

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

// The kernels' mean_of (kernels/pool.cl), so rows from folders equal generate's rows.
float mean_of(uint32_t sum, int count) {
  const uint32_t q = sum / static_cast<uint32_t>(count), r = sum % static_cast<uint32_t>(count);
  return std::clamp(static_cast<float>(q) + static_cast<float>(r) / static_cast<float>(count), 0.0f, 255.0f);
}

}  // namespace

std::vector<std::string> find_scenario_folders(const std::vector<std::string>& paths) {
  std::vector<std::string> out;
  std::function<void(const fs::path&)> walk = [&](const fs::path& p) {
    if (!find_image(p, "upper").empty()) {
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
    if (out.size() == before) throw InputError(p + ": no scenario folders (none holds upper.png or upper.jpg)");
  }
  return out;
}

bool read_scenario_folder(const std::string& dir, const Catalogue& cat, BatchOutput& out, size_t i) {
  const fs::path d(dir);
  const int W = cat.images.mmw_width, H = cat.images.mmw_height;
  std::array<Image, 2> views;
  const char* stems[2] = {"upper", "lower"};
  for (int v = 0; v < 2; ++v) {
    const std::string path = find_image(d, stems[v]);
    if (path.empty()) throw InputError((d / stems[v]).string() + ".png: missing");
    views[v] = to_gray(read_image(path, stems[v]), false);
    if (views[v].width != W || views[v].height != H)
      throw InputError(path + ": is " + std::to_string(views[v].width) + "x" + std::to_string(views[v].height) +
                       ", the catalogue's MMW views are " + std::to_string(W) + "x" + std::to_string(H));
  }
  // Block and region means, as integer sums divided in float: the same numbers the
  // kernels give for the same pixels.
  const FeatureLayout& f = out.layout;
  float* row = out.features.data() + i * f.image_features();
  int k = 0;
  for (const Image& img : views)
    for (int by = 0; by < f.blocks_y; ++by)
      for (int bx = 0; bx < f.blocks_x; ++bx) {
        const int x0 = bx * f.block, y0 = by * f.block;
        const int x1 = std::min(x0 + f.block, W), y1 = std::min(y0 + f.block, H);
        uint32_t sum = 0;
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) sum += img.at(x, y);
        row[k++] = mean_of(sum, (x1 - x0) * (y1 - y0));
      }
  for (const Region& r : cat.regions) {
    const Image& img = views[r.view == View::upper ? 0 : 1];
    uint32_t sum = 0;
    for (int y = r.mmw.y; y < r.mmw.y + r.mmw.h; ++y)
      for (int x = r.mmw.x; x < r.mmw.x + r.mmw.w; ++x) sum += img.at(x, y);
    row[k++] = mean_of(sum, r.mmw.w * r.mmw.h);
  }
  const fs::path metal = d / "metal.txt";
  const std::array<uint8_t, kZones> zones =
      parse_metal_text(io::read_file(metal.string(), "metal file", io::kMaxTextBytes), metal.string());
  std::copy(zones.begin(), zones.end(), out.metal.begin() + static_cast<std::ptrdiff_t>(i * kZones));
  const fs::path threat = d / "threat.txt";
  return parse_threat_text(io::read_file(threat.string(), "label file", io::kMaxTextBytes), threat.string());
}

std::array<uint8_t, kZones> parse_metal_text(std::string_view text, const std::string& source) {
  // 19 integers 0..200, separated by commas and/or spaces.
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
      if (zones.size() > kZones) break;
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  if (zones.size() != kZones)
    throw InputError(source + ":1: expected 19 zone values, found " +
                     (zones.size() > kZones ? "more" : std::to_string(zones.size())));
  std::array<uint8_t, kZones> out;
  for (int z = 0; z < kZones; ++z) out[z] = static_cast<uint8_t>(zones[z]);
  return out;
}

bool parse_threat_text(std::string_view text, const std::string& source) {
  const std::string raw = one_line(text, source);
  const std::string t = normalise_name(raw);
  if (t == "yes" || t == "positive" || t == "threat" || t == "1") return true;
  if (t == "no" || t == "negative" || t == "0") return false;
  throw InputError(source + ":1: \"" + raw + "\" is not yes or no");
}

}  // namespace portalsim
