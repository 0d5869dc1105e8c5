#include "speed/bench_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "backend/opencl/runtime.h"
#include "base/error.h"
#include "schedule/run_spec.h"
#include "speed/report.h"
#include "speed/run.h"

namespace portalsim::speed {

namespace {

struct BenchFlags {
  std::string device, dir, paths;
  bool list_devices = false, json = false, quick = false, quiet = false, without_fp64 = false;
  int repetitions = 3;
};

int list_devices() {
  const std::vector<OpenCLDeviceInfo> devices = list_opencl_devices();  // throws when there is none
  for (const OpenCLDeviceInfo& d : devices)
    std::printf("%s\t%s, %u compute units, fp64 %s\n", d.name.c_str(), d.type.c_str(), d.compute_units,
                d.fp64 ? "yes" : "no");
  return 0;
}

int bench(const BenchFlags& f) {
  if (f.list_devices) return list_devices();
  BenchOptions o;
  o.quick = f.quick;
  o.repetitions = f.repetitions;
  o.progress = !f.quiet;
  o.dir = f.dir.empty() ? std::filesystem::temp_directory_path().string() : f.dir;
  std::error_code ec;
  if (!std::filesystem::is_directory(o.dir, ec)) throw InputError("--dir: " + o.dir + " is not a folder");
  o.paths = split_list(f.paths);
  const std::vector<SpeedPath> chosen = chosen_paths(o.paths);  // checks the keys before the device opens
  auto rt = std::make_shared<OpenCLRuntime>(OpenCLOptions{f.device, ""});
  OpenCLDeviceInfo device = rt->info();
  if (f.without_fp64 && device.fp64) {
    device.fp64 = false;
    device.name += " (as without fp64: --without-fp64)";
  }
  if (!device.fp64 && !f.quiet) std::fprintf(stderr, "portalsim bench: %s\n", fp64_note(chosen, device).c_str());
  const BenchReport report = run_bench(o, rt, device);
  if (f.json)
    std::printf("%s\n", report_json(report).dump(2).c_str());
  else
    std::fputs(report_text(report).c_str(), stdout);
  return 0;
}

}  // namespace

std::function<int()> add_bench(CLI::App& app) {
  auto f = std::make_shared<BenchFlags>();
  CLI::App* sub = app.add_subcommand(
      "bench", "the speed table of this machine: kernels, plain loops, fp64 reference and end to end, per path");
  sub->add_option("--device", f->device, "OpenCL device: a substring of its platform or device name (--list-devices)");
  sub->add_flag("--list-devices", f->list_devices, "list the OpenCL devices, with their compute units and fp64");
  sub->add_flag("--json", f->json, "print the results as JSON instead of tables");
  sub->add_flag("--quick", f->quick, "small batches and counts, for a check that it runs (its rates mean little)");
  sub->add_option("--repetitions", f->repetitions, "repetitions of each measurement; the tables give medians")
      ->check(CLI::Range(1, 100));
  sub->add_option("--dir", f->dir, "folder for the end-to-end runs and the disk test (default: the temporary folder)");
  sub->add_option("--paths", f->paths,
                  "comma-separated paths to measure: features, images, noisy_images, physics_images, annotations");
  sub->add_flag("--without-fp64", f->without_fp64, "measure as on a device without fp64 (what such a device runs)");
  sub->add_flag("--quiet", f->quiet, "no progress line on stderr");
  return [f] { return bench(*f); };
}

}  // namespace portalsim::speed
