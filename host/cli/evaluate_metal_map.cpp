#include "cli/evaluate_metal_map.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "backend/opencl/runtime.h"
#include "base/embedded.h"
#include "base/error.h"
#include "cli/common.h"
#include "evaluate/metal_map.h"
#include "io/input_file.h"
#include "sink/staging.h"

namespace portalsim {
namespace cli {

namespace {

struct MetalMapOptions {
  evaluate::MetalMapSettings map;
  std::string sensitivity;  // "150,180,195"
  std::string clean = "bare";
  CLI::Option* metal_map = nullptr;
  // Options evaluate may already have: found by name when the map runs.
  std::string out, seed, catalogue, assets, backend, device, metal_noise, threads;
  bool plot = true;
  CLI::App* app = nullptr;
};

// The option `name` of `app`, added (bound to `into`) where `app` has none.
void shared_option(CLI::App& app, const std::string& name, std::string& into, const std::string& help) {
  if (!app.get_option_no_throw(name)) app.add_option(name, into, help);
}

// The text given to `name`, or `fallback` where it was not given.
std::string given(const CLI::App& app, const std::string& name, const std::string& fallback) {
  const CLI::Option* o = app.get_option_no_throw(name);
  return o && o->count() > 0 && !o->results().empty() ? o->results().back() : fallback;
}

int to_int(const std::string& text, const std::string& flag) {
  try {
    size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw InputError(flag + ": not a whole number: '" + text + "'");
}

std::vector<int> levels_of(const std::string& text) {
  std::vector<int> out;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    out.push_back(to_int(text.substr(at, comma - at), "--sensitivity"));
    at = comma + 1;
  }
  return out;
}

int run_metal_map(MetalMapOptions& o) {
  const CLI::App& app = *o.app;
  evaluate::MetalMapSettings s = o.map;
  s.object = o.metal_map->results().back();
  if (!o.sensitivity.empty()) s.settings = levels_of(o.sensitivity);
  s.benign_clean = o.clean == "benign";
  s.seed = io::parse_u64(given(app, "--seed", "0"), "--seed");
  s.metal_noise = to_int(given(app, "--metal-noise", std::to_string(s.metal_noise)), "--metal-noise");
  const std::string threads = given(app, "--threads", "0");
  const int thread_count = to_int(threads, "--threads");
  if (thread_count < 0) throw InputError("--threads: must be 0 (every core) or more, not " + threads);
  s.threads = static_cast<unsigned>(thread_count);
  const std::string out = given(app, "--out", "");
  if (out.empty()) throw InputError("--out: the metal map needs a report folder");
  const std::string backend = given(app, "--backend", "opencl");
  if (backend != "opencl" && backend != "reference")
    throw InputError("--backend: opencl or reference, not '" + backend + "'");
  const std::string catalogue = given(app, "--catalogue", ""), assets = given(app, "--assets", "");
  const Catalogue cat = catalogue.empty() ? default_catalogue(assets) : load_catalogue(catalogue, assets);
  // Every setting is checked before anything is written.
  evaluate::check_metal_map(cat, s);
  std::shared_ptr<OpenCLRuntime> rt;
  if (backend == "opencl") rt = std::make_shared<OpenCLRuntime>(OpenCLOptions{given(app, "--device", ""), ""});

  StagedFolder folder(out);
  const nlohmann::json report = evaluate::metal_map(cat, s, rt.get());
  write_text_atomic(folder.path("metal_map.json"), report.dump(1) + "\n");
  write_text_atomic(folder.path("metal_map.md"), evaluate::metal_map_markdown(report));
  // The plot, drawn by the embedded matplotlib script (tools/plot_metal_map.py).
  const bool plot = o.plot && !(app.get_option_no_throw("--no-plot") && app.get_option_no_throw("--no-plot")->count());
  if (plot) {
    run_plot_script(embedded::plot_metal_map, folder.dir(), {folder.dir()}, "metal_map.png");
    folder.path("metal_map.png");
  }
  folder.commit();
  const nlohmann::json& c = report["critical"];
  std::printf("%s: metal_map.json, metal_map.md%s\n", out.c_str(), plot ? ", metal_map.png" : "");
  std::printf("sensitivity %d (clean false alarms %.4f at most %.4g)", report["threshold"]["sensitivity"].get<int>(),
              report["threshold"]["clean_false_alarm_rate"].get<double>(), s.pfa);
  if (!c.is_null())
    std::printf("; critical orientation %s, position x %.3f m z %.3f m (Pd %.3f)",
                c["orientation"].get<std::string>().c_str(), c["position"]["x_m"].get<double>(),
                c["position"]["z_m"].get<double>(), c["position"]["pd"].get<double>());
  std::printf("\n");
  return 0;
}

}  // namespace

std::function<std::optional<int>()> add_metal_map(CLI::App& evaluate) {
  auto o = std::make_shared<MetalMapOptions>();
  o->app = &evaluate;
  evaluate::MetalMapSettings& m = o->map;
  o->metal_map = evaluate.add_option(
      "--metal-map", m.object, "walk-through metal detector sensitivity map of this catalogue object (physics model)");
  evaluate.add_option("--grid-step", m.grid_step, "metal map: metres between cells across and up (default 0.05)");
  evaluate.add_option("--speed", m.speed, "metal map: walking speed, m/s (default 1, the standards' pace)");
  evaluate.add_option("--sample-rate", m.sample_rate, "metal map: zone readings a second, Hz (default 50)");
  evaluate.add_option("--passes", m.passes, "metal map: noisy passes a cell (default 200)");
  evaluate.add_option("--clean-pfa", m.pfa, "metal map: clean testers' false-alarm rate at most, 0..1 (default 0.01)");
  evaluate
      .add_option("--clean-testers", o->clean,
                  "metal map: who sets the alarm level: bare (the subjects without metal, default) or benign (also "
                  "each subject with each benign item)")
      ->check(CLI::IsMember({"bare", "benign"}));
  evaluate.add_option("--sensitivity", o->sensitivity,
                      "metal map: alarm levels to report, comma-separated, each 1..199 (default 150,180,195)");
  shared_option(evaluate, "--out", o->out, "report folder");
  shared_option(evaluate, "--seed", o->seed, "run seed: unsigned 64-bit integer, decimal or 0x hex (default 0)");
  shared_option(evaluate, "--catalogue", o->catalogue, "catalogue TOML file (default: the built-in one)");
  shared_option(evaluate, "--assets", o->assets, "folder in which the catalogue's image files are looked up first");
  shared_option(evaluate, "--backend", o->backend,
                "opencl (kernels on PoCL) or reference (plain CPU, double precision)");
  shared_option(evaluate, "--device", o->device, "OpenCL device: a substring of its platform or device name");
  shared_option(evaluate, "--metal-noise", o->metal_noise,
                "metal detector noise: triangular integer noise of this half-width (metal map default 3)");
  shared_option(evaluate, "--threads", o->threads, "threads (default: all cores)");
  if (!evaluate.get_option_no_throw("--no-plot"))
    evaluate.add_flag("!--no-plot", o->plot, "skip the plots (needs no python3 with matplotlib)");
  return [o]() -> std::optional<int> {
    if (o->metal_map->count() == 0) return std::nullopt;
    return run_metal_map(*o);
  };
}

}  // namespace cli
}  // namespace portalsim
