#include "calibrate/camera_files.h"

#include <charconv>
#include <iterator>
#include <sstream>

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

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

}  // namespace

std::string camera_spec(const CameraFit& fit, const ModelSettings& model, const std::string& spec_name,
                        const std::string& catalogue_name) {
  std::ostringstream t;
  t << "# The camera fitted by portalsim calibrate. Use it as\n"
    << "#   portalsim generate --spec " << spec_name << " --catalogue " << catalogue_name
    << " --what images --out DIR\n"
    << "# (the catalogue holds the fitted aperture).\n"
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

std::string camera_catalogue(const std::string& catalogue_text, const CameraFit& fit) {
  const std::pair<std::string, std::string> keys[] = {
      {"aperture_m",
       number(fit.aperture_m) + "  # PSF FWHM " + rounded(fit.fwhm_pixels, 2) + " view pixels (fitted by calibrate)"}};
  std::istringstream in(catalogue_text);
  std::ostringstream out;
  std::string line;
  bool in_physics = false;
  bool done[1] = {false};
  auto flush_missing = [&]() {
    for (size_t k = 0; k < std::size(keys); ++k)
      if (!done[k]) {
        out << keys[k].first << " = " << keys[k].second << "\n";
        done[k] = true;
      }
  };
  while (std::getline(in, line)) {
    const std::string t = trim(line);
    if (!t.empty() && t[0] == '[') {
      if (in_physics) flush_missing();
      in_physics = t == "[physics]";
      out << line << "\n";
      continue;
    }
    bool replaced = false;
    if (in_physics)
      for (size_t k = 0; k < std::size(keys); ++k) {
        const std::string& key = keys[k].first;
        if (t.rfind(key, 0) == 0 && trim(t.substr(key.size())).rfind('=', 0) == 0) {
          out << key << " = " << keys[k].second << "\n";
          done[k] = replaced = true;
        }
      }
    if (!replaced) out << line << "\n";
  }
  if (in_physics) flush_missing();
  if (!done[0]) {
    out << "\n[physics]\n";
    flush_missing();
  }
  return out.str();
}

}  // namespace portalsim::calibrate
