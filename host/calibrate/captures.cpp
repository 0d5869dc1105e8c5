#include "calibrate/captures.h"

#include <algorithm>
#include <filesystem>

#include "assets/image_io.h"
#include "base/error.h"
#include "base/spoken_list.h"
#include "sink/h5_file.h"

namespace portalsim::calibrate {

namespace {

namespace fs = std::filesystem;

// "upper.png and lower.png": the files each scenario folder holds.
std::string files_of(const std::vector<std::string>& views) {
  std::vector<std::string> files;
  for (const std::string& v : views) files.push_back(v + ".png");
  return spoken_list(files);
}

void add_image(ViewCaptures& v, const Image& img, const std::string& file) {
  if (img.channels != 1)
    throw InputError(file + ": has " + std::to_string(img.channels) +
                     " channels; calibrate needs the gray MMW views (1 channel)");
  if (v.images.empty()) {
    v.width = img.width;
    v.height = img.height;
  } else if (img.width != v.width || img.height != v.height) {
    throw InputError(file + ": is " + std::to_string(img.width) + "x" + std::to_string(img.height) + ", but " +
                     v.files.front() + " is " + std::to_string(v.width) + "x" + std::to_string(v.height) +
                     " (every capture of a view must be the same size)");
  }
  v.images.push_back(img.pixels);
  v.files.push_back(file);
}

Captures read_h5(const std::string& path, const std::vector<std::string>& views) {
  const H5Layout layout = read_h5_layout(path);
  Captures c;
  c.source = path;
  for (const std::string& name : views) {
    auto it = std::find_if(layout.datasets.begin(), layout.datasets.end(),
                           [&](const H5Dataset& d) { return d.name == name; });
    if (it == layout.datasets.end())
      throw InputError(path + ": has no dataset \"" + name + "\" (make it with generate --what images --format h5)");
    if (it->type != TensorType::u8 || it->dims.size() != 2)
      throw InputError(path + ": dataset " + name + " is not N x H x W gray levels (uint8)");
    ViewCaptures v;
    v.name = name;
    const int h = static_cast<int>(it->dims[0]), w = static_cast<int>(it->dims[1]);
    std::vector<char> rows(it->row_bytes() * layout.rows);
    if (layout.rows > 0) read_h5_rows(path, *it, 0, layout.rows, rows.data());
    for (uint64_t r = 0; r < layout.rows; ++r) {
      Image img(w, h, 1);
      std::copy_n(rows.data() + r * it->row_bytes(), it->row_bytes(), reinterpret_cast<char*>(img.pixels.data()));
      add_image(v, img, path + ": " + name + "[" + std::to_string(r) + "]");
    }
    c.views.push_back(std::move(v));
  }
  return c;
}

// The scenario folders: DIR/images/* for a generate run, else DIR/*, in name order.
std::vector<fs::path> scenario_folders(const fs::path& dir) {
  const fs::path root = fs::is_directory(dir / "images") ? dir / "images" : dir;
  std::vector<fs::path> found;
  for (const auto& e : fs::directory_iterator(root))
    if (e.is_directory() && e.path().filename().string().front() != '.') found.push_back(e.path());
  std::sort(found.begin(), found.end());
  return found;
}

bool flat(const std::vector<uint8_t>& img) {
  return std::all_of(img.begin(), img.end(), [&](uint8_t v) { return v == img.front(); });
}

}  // namespace

void check_captures(const Captures& c) {
  if (c.count() < kMinCaptures)
    throw InputError(c.source + ": " + std::to_string(c.count()) + " capture(s); calibrate needs at least " +
                     std::to_string(kMinCaptures) + " to tell the scenes' spread from the camera's noise");
  // A 1x1 raw grid makes every capture flat; one flat capture among others is a blank or
  // saturated frame.
  bool all_flat = true, any_flat = false;
  for (const ViewCaptures& v : c.views)
    for (const auto& img : v.images) {
      all_flat = all_flat && flat(img);
      any_flat = any_flat || flat(img);
    }
  if (all_flat) {
    bool one_level = true;
    for (const ViewCaptures& v : c.views)
      for (const auto& img : v.images) one_level = one_level && img.front() == c.views[0].images[0].front();
    if (one_level)
      throw InputError(c.views[0].files[0] + ": every capture is one gray level (" +
                       std::to_string(c.views[0].images[0].front()) + "); there is nothing to fit");
    return;
  }
  if (any_flat)
    for (const ViewCaptures& v : c.views)
      for (size_t i = 0; i < v.images.size(); ++i)
        if (flat(v.images[i]))
          throw InputError(v.files[i] + ": is flat (every pixel " + std::to_string(v.images[i].front()) +
                           ") where the other captures are not: a blank or saturated frame");
}

std::vector<std::string> mmw_views(const Catalogue& cat) {
  std::vector<std::string> names;
  for (const Sensor& s : cat.sensors)
    if (camera_kind(s.camera).raw_grid) names.push_back(s.name);  // the fit is of a raw grid
  return names;
}

Captures read_captures(const std::string& dir, const Catalogue& cat) {
  const std::vector<std::string> views = mmw_views(cat);
  if (views.empty()) throw InputError(cat.source + ": the catalogue has no MMW view to calibrate");
  const fs::path p(dir);
  Captures c;
  if (fs::is_regular_file(p) || fs::is_regular_file(p / "data.h5")) {
    c = read_h5(fs::is_regular_file(p) ? dir : (p / "data.h5").string(), views);
  } else {
    if (!fs::is_directory(p)) throw InputError(dir + ": no such folder (give a folder of captures or a data.h5)");
    c.source = dir;
    for (const std::string& name : views) c.views.push_back(ViewCaptures{name, 0, 0, {}, {}});
    for (const fs::path& f : scenario_folders(p))
      for (ViewCaptures& v : c.views) {
        const std::string file = (f / (v.name + ".png")).string();
        if (!fs::exists(file))
          throw InputError(file + ": missing (each scenario folder needs " + files_of(views) + ")");
        add_image(v, read_image(file, "capture"), file);
      }
  }
  check_captures(c);
  return c;
}

}  // namespace portalsim::calibrate
