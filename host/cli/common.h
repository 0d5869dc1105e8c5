// What every subcommand shares: the catalogue and assets it runs on, the backend, and
// parsing of numbers given on the command line.
#pragma once
#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/backend.h"
#include "backend/opencl/runtime.h"
#include "scene/catalogue.h"
#include "schedule/run_spec.h"
#include "sink/staging.h"

namespace portalsim::cli {

struct CommonOptions {
  std::string catalogue;  // empty = built-in
  std::string assets;
  std::string backend = "opencl";
  std::string device;
  std::string seed = "0";
  bool timing = false;
};

void add_common_options(CLI::App& app, CommonOptions& o);
// --tier and a flag for every knob of plan/knobs.h; each knob's text lands in values[key].
void add_knob_options(CLI::App& app, std::string& tier, std::map<std::string, std::string>& values);
// The knobs given on the command line, by key, as text.
std::map<std::string, std::string> given_knobs(const CLI::App& app, const std::map<std::string, std::string>& values);

// Parses `args` into `app` and checks every value as the command line does; a parse error
// becomes InputError with CLI11's message (--help, which asks for none, a message of ours).
void parse_args(CLI::App& app, const std::vector<std::string>& args);

// The catalogue, its assets and a backend, with the time each took.
struct Session {
  Catalogue catalogue;
  AssetSet assets;
  std::shared_ptr<OpenCLRuntime> runtime;  // null for the reference backend
  std::unique_ptr<Backend> backend;
  double catalogue_seconds = 0, assets_seconds = 0, backend_seconds = 0;
};
Session open_session(const CommonOptions& o);
// Catalogue and assets only (no backend yet): lets a command check its arguments first.
// The catalogue and its images; where `spec` asks for random bodies, its drawn bodies in
// place of the catalogue's subjects. The subjects' fold patterns are drawn unless the caller
// knows the run gives no --clothing-folds (fold_patterns false; build_assets).
void open_catalogue(Session& s, const CommonOptions& o, const RunSpec* spec = nullptr, bool fold_patterns = true);
void open_backend(Session& s, const CommonOptions& o);
// The flags that choose a command's subjects: the catalogue's, or random bodies (--bodies
// random, --body-count, --body-seed). A run spec's commands read them into the spec
// (spec_flags.cpp); simulate and serve through bodies_spec.
struct BodyOptions {
  std::string bodies = "catalogue", count, seed;
};
// `seed_default` says what --body-seed defaults to.
void add_body_options(CLI::App& app, BodyOptions& o, const std::string& seed_default = "0");
// --body-count's value, checked: 1 .. kMaxRandomBodies.
int parse_body_count(const std::string& text);
// Them as a spec for open_catalogue; checked, errors naming the flags.
RunSpec bodies_spec(const BodyOptions& o);

// The bodies a generate folder was made with, as a spec for open_catalogue: its manifest's
// random bodies and seed (the catalogue's subjects where it has none, or no manifest).
RunSpec bodies_of_folder(const std::string& dir);
// --timing's line of the paths `backend` takes for `plan` ("paths: upper: thesis_images, ...").
void print_paths(const Backend& backend, const Plan& plan);

// `s` as one word for /bin/sh, whatever it holds ('...' with each ' as '\'').
std::string shell_quote(const std::string& s);

// Runs an embedded Python script with Debian's /usr/bin/python3 (whose matplotlib and torch
// it is) where it exists: written into `dir` as .script.py, run with `args` (each one word,
// however named), then removed. Whether it exited 0.
bool run_python_script(std::string_view script, const std::string& dir, const std::vector<std::string>& args);
// The same for a plot: throws OutputError naming `what` if it fails, and --no-plot where the
// command has it.
void run_plot_script(std::string_view script, const std::string& dir, const std::vector<std::string>& args,
                     const std::string& what, bool offers_no_plot = true);

// Every base image, sprite and noise pattern of the session, as `portalsim catalogue
// --images` writes them; a subject's view is named by subject_image_name.
void write_catalogue_images(const Session& s, StagedFolder& folder);
// "subject1_mmw_upper.png": subject (0-based) and view; the view's asset key is also the
// subject's catalogue field that can name the file.
std::string subject_image_name(size_t subject, const Sensor& view);

}  // namespace portalsim::cli
