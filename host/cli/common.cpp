#include "cli/common.h"

#include <chrono>

#include "backend/opencl/opencl_backend.h"
#include "base/error.h"

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

void add_fidelity_options(CLI::App& app, std::string& tier, std::map<std::string, std::string>& knobs) {
  app.add_option("--tier", tier, "fidelity tier: fast, standard (default) or exact")
      ->check(CLI::IsMember({"fast", "standard", "exact"}));
  app.add_option("--precision", knobs["precision"], "kernel arithmetic: fp32, fp64 or fixed16 (overrides the tier)")
      ->check(CLI::IsMember({"fp32", "fp64", "fixed16"}));
  app.add_option("--pooling", knobs["pooling"], "features: sparse or dense (overrides the tier)")
      ->check(CLI::IsMember({"sparse", "dense"}));
  app.add_option("--fast-math", knobs["fast_math"], "-cl-fast-relaxed-math: on or off (overrides the tier)")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--noise-model", knobs["noise_model"],
                 "pixel noise in features-only runs: per-pixel or block-mean (overrides the tier)")
      ->check(CLI::IsMember({"per-pixel", "block-mean"}));
}

void open_catalogue(Session& s, const CommonOptions& o) {
  auto t0 = std::chrono::steady_clock::now();
  s.catalogue = o.catalogue.empty() ? default_catalogue(o.assets) : load_catalogue(o.catalogue, o.assets);
  s.catalogue_seconds = since(t0);
  t0 = std::chrono::steady_clock::now();
  s.assets = build_assets(s.catalogue);
  s.assets_seconds = since(t0);
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

Session open_session(const CommonOptions& o) {
  Session s;
  open_catalogue(s, o);
  open_backend(s, o);
  return s;
}

}  // namespace portalsim::cli
