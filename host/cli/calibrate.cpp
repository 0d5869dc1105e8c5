// `portalsim calibrate --real DIR [--out camera.toml]`: fits the physics model's camera
// (raw grid, blur, display window, noise) to a folder of MMW captures and writes what
// `generate` takes: a spec (camera.toml), a catalogue with the fitted aperture and each
// view's own camera where it differs (camera.catalogue.toml) and a report with its plot
// (camera-report/).
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "assets/assets.h"
#include "base/embedded.h"
#include "base/error.h"
#include "base/spoken_list.h"
#include "calibrate/camera_files.h"
#include "calibrate/compare.h"
#include "cli/commands.h"
#include "sink/staging.h"

namespace portalsim::cli {

namespace {

namespace fs = std::filesystem;

struct Options {
  std::string real, out = "camera.toml", catalogue, assets;
  uint64_t seed = 1;
  bool accept_non_camera = false;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

nlohmann::json fit_json(const calibrate::CameraFit& f, size_t captures) {
  nlohmann::json views = nlohmann::json::array();
  for (size_t v = 0; v < f.views.size(); ++v) {
    const calibrate::ViewFit& vf = f.views[v];
    views.push_back(
        {{"name", vf.name},
         {"raw_grid", {{"width", vf.raw_w}, {"height", vf.raw_h}}},
         {"raw_grid_residual",
          {{"x", vf.grid_x.ms}, {"y", vf.grid_y.ms}, {"bound_x", vf.grid_x.bound}, {"bound_y", vf.grid_y.bound}}},
         {"noise_gray", vf.noise_gray},
         {"noise_gray_se", vf.noise_se},
         {"netd", vf.netd},
         {"noise_agrees_with_run", vf.noise_agrees},
         {"cells", vf.cells},
         {"own_raw", vf.own_raw},
         {"own_netd", vf.own_netd},
         {"camera",
          {{"raw_grid", {{"width", f.view_raw(v)[0]}, {"height", f.view_raw(v)[1]}}}, {"netd", f.view_netd(v)}}}});
  }
  return {{"captures", captures},
          {"raw_grid", {{"width", f.raw_w}, {"height", f.raw_h}}},
          {"raw_grid_view", f.views[f.raw_view].name},
          {"noise_view", f.views[f.noise_view].name},
          {"psf_fwhm_pixels", f.fwhm_pixels},
          {"aperture_m", f.aperture_m},
          {"blur_told", f.blur_told},
          {"blur_search", {{"fwhm_pixels", f.blur_fwhm}, {"cost", f.blur_cost}}},
          {"display_min", f.display_min},
          {"display_max", f.display_max},
          {"gain_gray_per_k", f.gain},
          {"gain_relative_error", f.gain_rel_error},
          {"window_told", f.window_told},
          {"noise_gray", f.noise_gray},
          {"netd", f.netd},
          {"cells", f.cells},
          {"subject", f.subject},
          {"views", views}};
}

std::string markdown(const Options& o, const calibrate::CameraFit& f, const calibrate::Captures& captures, bool plotted,
                     const std::string& spec_name, const std::string& catalogue_name) {
  std::vector<std::string> names, own_raw, own_netd, pooled;
  for (size_t k = 0; k < f.views.size(); ++k) {
    const calibrate::ViewFit& v = f.views[k];
    names.push_back(v.name);
    if (v.own_raw) own_raw.push_back(v.name + " " + std::to_string(v.raw_w) + "x" + std::to_string(v.raw_h));
    if (v.own_netd) own_netd.push_back(v.name + " " + fixed(f.view_netd(k), 4) + " K");
    if (v.noise_agrees) pooled.push_back(v.name);
  }
  const std::string run_raw = f.views[f.raw_view].name, run_noise = f.views[f.noise_view].name;
  std::ostringstream md;
  md << "# Camera calibrated from " << o.real << "\n\n"
     << captures.count() << " captures (" << spoken_list(names) << " views), matched to the catalogue's subjects.\n\n"
     << "| parameter | fitted | how |\n| --- | --- | --- |\n"
     << "| raw grid | " << f.raw_w << "x" << f.raw_h << (own_raw.empty() ? "" : " (own: " + spoken_list(own_raw) + ")")
     << " | the fewest raw pixels whose bilinear interpolation reproduces every row and column to rounding |\n"
     << "| PSF FWHM | " << fixed(f.fwhm_pixels, 2) << " view pixels (aperture " << fixed(f.aperture_m * 1000, 2)
     << " mm)" << (f.blur_told ? "" : " (not told: the captures hardly change with the blur)")
     << " | the bare subject blurred and sampled onto the raw grid, against the captures' raw grids |\n"
     << "| display window | " << fixed(f.display_min, 3) << " .. " << fixed(f.display_max, 3) << " K (gain "
     << fixed(f.gain, 3) << " gray/K"
     << (f.window_told ? ", +-" + fixed(100 * f.gain_rel_error, 1) + "%)"
                       : "; not told: the captures show too little body against room, so the catalogue's "
                         "width is kept and only the level fitted)")
     << " | the captures' raw grids against the subject's kelvin, a robust line |\n"
     << "| noise | " << fixed(f.netd, 4) << " K rms per raw pixel (" << fixed(f.noise_gray, 3) << " gray)"
     << (own_netd.empty() ? "" : " (own: " + spoken_list(own_netd) + ")")
     << " | the robust spread of what the bare subject leaves, less rounding |\n\n"
     << "Each view's raw grid and noise are fitted from its own captures, the blur and the window from all of "
        "them. "
     << spec_name << " holds " << run_raw << "'s raw grid and "
     << (pooled.size() > 1
             ? "the noise pooled over " + spoken_list(pooled) + ", whose own noise agrees with " + run_noise + "'s"
             : run_noise + "'s noise, which no other view's agrees with")
     << " (within " << fixed(calibrate::kNoiseAgreement, 0) << " standard errors, "
     << fixed(100 * calibrate::kNoiseTolerance, 0) << "% or " << fixed(calibrate::kMinCameraNoiseGray, 1) << " gray); "
     << catalogue_name
     << " gives a view its own `raw` or `netd` where its camera differs, or where your catalogue gave it one.\n\n"
     << "| view | raw grid | noise, K rms per raw pixel | gray levels | in " << catalogue_name << " |\n"
     << "| --- | --- | --- | --- | --- |\n";
  for (size_t v = 0; v < f.views.size(); ++v) {
    const calibrate::ViewFit& vf = f.views[v];
    std::string own;
    if (vf.own_raw) own = "raw = [" + std::to_string(vf.raw_w) + ", " + std::to_string(vf.raw_h) + "]";
    if (vf.own_netd) own += (own.empty() ? "" : ", ") + std::string("netd = ") + fixed(f.view_netd(v), 4);
    md << "| " << vf.name << " | " << vf.raw_w << "x" << vf.raw_h << " | " << fixed(vf.netd, 4) << " | "
       << fixed(vf.noise_gray, 3) << " +- " << fixed(vf.noise_se, 3) << " | " << (own.empty() ? "the run's" : own)
       << " |\n";
  }
  md << "\nUse it: `portalsim generate --spec " << spec_name << " --catalogue " << catalogue_name
     << " --what images --out DIR`.\n\n";
  if (plotted)
    md << "![captures against the fitted camera](calibrate.png)\n\n";
  else
    md << "(No plot: /usr/bin/python3 with matplotlib was not found; report.json holds the statistics.)\n\n";
  md << "report.json holds the histograms, the noise power spectra along rows (each image less the fitted "
        "camera's noise-free image of its subject) and the edge profiles across the body's left outline, "
        "for the captures and for the fitted camera's images of the same subjects (bare: the captures' "
        "objects are not simulated).\n";
  return md.str();
}

// Runs /usr/bin/python3 SCRIPT FOLDER; false when python3 is absent or the script fails.
bool run_plot(const std::string& script, const std::string& folder) {
  if (!fs::exists("/usr/bin/python3")) return false;
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    ::execl("/usr/bin/python3", "python3", script.c_str(), folder.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  return ::waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

int run_calibrate(const Options& o) {
  // Everything that can refuse the input comes first: nothing is written before the fit.
  const Catalogue cat = o.catalogue.empty() ? default_catalogue(o.assets) : load_catalogue(o.catalogue, o.assets);
  const calibrate::Captures captures = calibrate::read_captures(o.real, cat);
  const std::string catalogue_text =
      o.catalogue.empty() ? std::string(embedded::default_catalogue) : read_text(o.catalogue);
  const AssetSet assets = build_assets(cat);
  const ModelSettings model;
  const calibrate::CameraFit fit = calibrate::fit_camera(captures, cat, assets, model);
  if (const std::string why = calibrate::not_camera_like(captures, fit); !why.empty() && !o.accept_non_camera)
    throw InputError(o.real +
                     ": these do not look like a raw-grid camera's captures (rendered images, such as the "
                     "thesis model's, do not): " +
                     why + "; nothing written (--accept-non-camera fits them anyway)");
  const calibrate::Simulated sim = calibrate::simulate_captures(captures, fit, cat, assets, model, o.seed);
  const std::string fitted_text =
      calibrate::camera_catalogue(catalogue_text, fit, o.catalogue.empty() ? "the built-in catalogue" : o.catalogue);

  const fs::path out(o.out);
  const std::string stem = out.stem().string();
  const fs::path catalogue_path = out.parent_path() / (stem + ".catalogue.toml");
  const fs::path report_dir = out.parent_path() / (stem + "-report");
  nlohmann::json report = {{"real", o.real},
                           {"fit", fit_json(fit, captures.count())},
                           {"statistics", calibrate::compare_statistics(captures, sim)}};
  {
    StagedFolder folder(report_dir.string());
    write_text_atomic(folder.path("report.json"), report.dump(1) + "\n");
    const std::string script = (fs::path(folder.dir()) / "plot_calibrate.py").string();
    write_text_atomic(script, std::string(embedded::plot_calibrate));
    const bool plotted = run_plot(script, folder.dir());
    if (plotted) folder.path("calibrate.png");
    const std::string md =
        markdown(o, fit, captures, plotted, out.filename().string(), catalogue_path.filename().string());
    write_text_atomic(folder.path("report.md"), md);
    write_text_atomic(catalogue_path.string(), fitted_text);
    write_text_atomic(out.string(),
                      calibrate::camera_spec(fit, model, out.filename().string(), catalogue_path.filename().string()));
    folder.commit();
    std::printf("%s", md.c_str());
  }
  return 0;
}

}  // namespace

std::function<int()> add_calibrate(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Fit the physics model's MMW camera (raw grid, blur, window, noise) to a folder of captures");
  cmd->add_option("--real", o->real,
                  "Folder of scenario folders with a PNG of each MMW view (upper.png and lower.png in the built-in "
                  "portal; simulate or generate --what images), "
                  "or a data.h5 of generate --format h5")
      ->required();
  cmd->add_option("--out", o->out,
                  "Spec to write (default camera.toml); beside it STEM.catalogue.toml and the report STEM-report/");
  cmd->add_option("--catalogue", o->catalogue, "Catalogue TOML whose subjects the captures show (default built-in)");
  cmd->add_option("--assets", o->assets, "Folder in which the catalogue's image files are looked up first");
  cmd->add_option("--seed", o->seed, "Seed of the report's simulated images (default 1)");
  cmd->add_flag("--accept-non-camera", o->accept_non_camera,
                "Fit captures that do not look like a raw-grid camera's (a raw grid the view's own size, or noise "
                "under 0.1 gray level), which are otherwise refused");
  return [o] { return run_calibrate(*o); };
}

}  // namespace portalsim::cli
