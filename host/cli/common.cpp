#include "cli/common.h"

#include <chrono>

#include "backend/opencl/opencl_backend.h"
#include "scene/error.h"

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

uint64_t parse_u64(const std::string& text, const std::string& field) {
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  std::string digits = hex ? text.substr(2) : text;
  while (digits.size() > 1 && digits[0] == '0') digits.erase(0, 1);
  const auto bad = [&]() {
    return InputError(field + ": \"" + text + "\" is not an unsigned 64-bit integer (0 to 18446744073709551615)");
  };
  if (digits.empty() || digits.size() > 20) throw bad();
  unsigned __int128 v = 0;
  for (char c : digits) {
    int d;
    if (c >= '0' && c <= '9')
      d = c - '0';
    else if (hex && c >= 'a' && c <= 'f')
      d = c - 'a' + 10;
    else if (hex && c >= 'A' && c <= 'F')
      d = c - 'A' + 10;
    else
      throw bad();
    v = v * (hex ? 16 : 10) + d;
    if (v > UINT64_MAX) throw bad();
  }
  return static_cast<uint64_t>(v);
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
