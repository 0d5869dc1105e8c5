#include "cli/common.h"

#include <chrono>
#include <cstdlib>
#include <filesystem>

#include "backend/opencl/opencl_backend.h"
#include "base/error.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "scene/bodies.h"
#include "schedule/run_state.h"

namespace portalsim::cli {

namespace {
double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

void add_common_options(CLI::App& app, CommonOptions& o) {
  app.add_option("--catalogue", o.catalogue, "catalogue TOML file (default: the built-in one)");
  app.add_option("--assets", o.assets, "folder in which the catalogue's image files are looked up first");
  app.add_option("--backend", o.backend, "opencl (kernels on PoCL) or reference (plain CPU, double precision)")
      ->check(CLI::IsMember({"opencl", "reference"}));
  app.add_option("--device", o.device, "OpenCL device: a substring of its platform or device name");
  app.add_option("--seed", o.seed, "run seed: unsigned 64-bit integer, decimal or 0x hex (default 0)");
  app.add_flag("--timing", o.timing, "print where the time went");
}

void add_knob_options(CLI::App& app, std::string& tier, std::map<std::string, std::string>& values) {
  app.add_option("--tier", tier, "fidelity tier: fast, standard (default) or exact")
      ->check(CLI::IsMember({"fast", "standard", "exact"}));
  for (const Knob& k : knobs()) {
    std::string help = k.help + ": " + k.values() + (k.fidelity ? " (overrides the tier)" : "");
    // Checked by set_knob, not CLI11, so that a flag, a spec key and a serve request get
    // one message for one mistake.
    app.add_option(k.flag(), values[k.key], help);
  }
}

std::map<std::string, std::string> given_knobs(const CLI::App& app, const std::map<std::string, std::string>& values) {
  std::map<std::string, std::string> given;
  for (const Knob& k : knobs())
    if (app.get_option(k.flag())->count() > 0) given[k.key] = values.at(k.key);
  return given;
}

void open_catalogue(Session& s, const CommonOptions& o, const RunSpec* spec, bool fold_patterns) {
  auto t0 = std::chrono::steady_clock::now();
  s.catalogue = o.catalogue.empty() ? default_catalogue(o.assets) : load_catalogue(o.catalogue, o.assets);
  if (spec && spec->random_bodies()) use_random_bodies(s.catalogue, spec->bodies_seed(), spec->random_bodies());
  // The first page's: a run makes the others as it reaches them (schedule/body_pages.h).
  if (spec && spec->per_scenario_bodies()) use_page_bodies(s.catalogue, spec->bodies_seed(), 0);
  s.catalogue_seconds = since(t0);
  t0 = std::chrono::steady_clock::now();
  s.assets = build_assets(s.catalogue, fold_patterns);
  s.assets_seconds = since(t0);
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool run_python_script(std::string_view script, const std::string& dir, const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  const std::string path = (fs::path(dir) / ".script.py").string();
  write_text_atomic(path, std::string(script));
  std::string cmd = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  cmd += " " + shell_quote(path);
  for (const std::string& a : args) cmd += " " + shell_quote(a);
  const int rc = std::system(cmd.c_str());
  std::error_code ec;
  fs::remove(path, ec);
  return rc == 0;
}

void run_plot_script(std::string_view script, const std::string& dir, const std::vector<std::string>& args,
                     const std::string& what, bool offers_no_plot) {
  if (!run_python_script(script, dir, args))
    throw OutputError(what + ": the plot failed (python3 with matplotlib is needed" +
                      (offers_no_plot ? "; or --no-plot)" : ")"));
}

void print_paths(const Backend& backend, const Plan& plan) {
  std::string line;
  for (const std::string& p : backend.paths(plan)) line += (line.empty() ? "" : ", ") + p;
  std::printf("paths: %s\n", line.c_str());
}

void open_backend(Session& s, const CommonOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.backend == "reference") {
    s.backend = make_reference_backend(s.catalogue, s.assets);
  } else {
    s.runtime = std::make_shared<OpenCLRuntime>(OpenCLOptions{o.device, ""});
    s.backend = make_opencl_backend(s.catalogue, s.assets, s.runtime);
  }
  s.backend_seconds = since(t0);
}

void add_body_options(CLI::App& app, BodyOptions& o, const std::string& seed_default) {
  app.add_option("--bodies", o.bodies,
                 "the subjects: catalogue (its own), random: --body-count bodies drawn from the ANSUR II survey's "
                 "statistics, each with its own pose and skin, in place of them, or per-scenario: a body drawn so "
                 "for every scenario (docs/model/bodies.md)");
  app.add_option("--body-count", o.count,
                 "how many random bodies, 1 .. " + std::to_string(kMaxRandomBodies) + " (default " +
                     std::to_string(kDefaultRandomBodies) + ")");
  app.add_option("--body-seed", o.seed, "the seed the random bodies are drawn from (default " + seed_default + ")");
}

int parse_body_count(const std::string& text) {
  const uint64_t n = io::parse_u64(text, "--body-count");
  if (n < 1 || n > kMaxRandomBodies)
    throw InputError("--body-count: \"" + text + "\" is not between 1 and " + std::to_string(kMaxRandomBodies));
  return static_cast<int>(n);
}

RunSpec bodies_spec(const BodyOptions& o) {
  RunSpec spec;
  spec.bodies = o.bodies;
  if (spec.per_scenario_bodies())
    throw InputError(
        "--bodies: per-scenario bodies are drawn per scenario of a data set (generate, run, evaluate "
        "--spec); here, give --bodies random and choose one with --subject");
  if (!o.count.empty()) spec.body_count = parse_body_count(o.count);
  if (!o.seed.empty()) spec.body_seed = io::parse_u64(o.seed, "--body-seed");
  spec.validate();  // names the flags: --bodies, --body-count, --body-seed
  return spec;
}

RunSpec bodies_of_folder(const std::string& dir) {
  RunSpec spec;
  std::error_code ec;
  const std::string path = (std::filesystem::path(dir) / "manifest.json").string();
  if (dir.empty() || !std::filesystem::exists(path, ec)) return spec;  // the reader says what is missing
  const nlohmann::json manifest = parse_manifest(io::read_text_file(path, "manifest", io::Bom::refuse), path);
  const nlohmann::json& made = manifest["spec"];
  const std::string bodies = made.value("bodies", std::string("catalogue"));
  if (bodies == "per-scenario") {
    spec.bodies = bodies;
  } else if (bodies == "random") {
    const nlohmann::json& count = made.value("body_count", nlohmann::json());
    if (!count.is_number_integer() || count.get<int64_t>() < 1 || count.get<int64_t>() > kMaxRandomBodies)
      throw InputError(path + ": spec.body_count: not a count of random bodies (1 to " +
                       std::to_string(kMaxRandomBodies) + ")");
    spec.bodies = bodies;
    spec.body_count = count.get<int>();
  } else {
    return spec;
  }
  for (const char* key : {"seed", "body_seed"})
    if (!made.contains(key) || !made[key].is_string())
      throw InputError(path + ": spec." + key + ": expected the seed as a string of digits");
  spec.seed = io::parse_u64(made["seed"].get<std::string>(), path + ": spec.seed");
  spec.body_seed = io::parse_u64(made["body_seed"].get<std::string>(), path + ": spec.body_seed");
  return spec;
}

Session open_session(const CommonOptions& o) {
  Session s;
  open_catalogue(s, o);
  open_backend(s, o);
  return s;
}

void parse_args(CLI::App& app, const std::vector<std::string>& args) {
  try {
    app.parse(std::vector<std::string>(args.rbegin(), args.rend()));  // CLI11 takes them last first
  } catch (const CLI::CallForHelp&) {                                 // CLI11's what() here is for its own main()
    // (the apps of parse_generate and parse_simulate are described "portalsim generate"...)
    const std::string command = app.get_description().empty() ? "portalsim COMMAND" : app.get_description();
    throw InputError("--help: not available here; `" + command + " --help` lists the flags");
  } catch (const CLI::ParseError& e) {
    throw InputError(e.what());
  }
  for (const CLI::Option* o : app.get_options())
    for (const std::string& v : o->results()) io::check_flag_value(v, o->get_name());
}

}  // namespace portalsim::cli
