#include "speed/run.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "backend/opencl/opencl_backend.h"
#include "base/error.h"
#include "base/parallel.h"
#include "schedule/pipeline.h"
#include "speed/bandwidth.h"

namespace portalsim::speed {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Scenarios/s of `once` (n scenarios a call), called until min_seconds have passed.
double rate_of(size_t n, double min_seconds, const std::function<void()>& once) {
  size_t done = 0;
  const auto t0 = Clock::now();
  double elapsed = 0;
  do {
    once();
    done += n;
    elapsed = since(t0);
  } while (elapsed < min_seconds);
  return static_cast<double>(done) / elapsed;
}

uint64_t folder_bytes(const fs::path& dir) {
  uint64_t total = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) total += e.file_size();
  return total;
}

std::string cpu_name() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  return "";
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

// "k/N path: what" on stderr, over itself on a terminal, a line each otherwise.
class Progress {
 public:
  Progress(bool on, int total) : on_(on), tty_(::isatty(2) == 1), total_(total) {}
  ~Progress() {
    if (on_ && tty_) std::fputs("\n", stderr);
  }
  void step(const std::string& what) {
    ++done_;
    if (!on_) return;
    std::fprintf(stderr, tty_ ? "\rportalsim bench: %d/%d %s\033[K" : "portalsim bench: %d/%d %s\n", done_, total_,
                 what.c_str());
    std::fflush(stderr);
  }

 private:
  bool on_, tty_;
  int total_, done_ = 0;
};

// Removes a folder when it goes out of scope (end-to-end runs, also on an error).
struct Scratch {
  fs::path dir;
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

Sizes Sizes::of(bool quick) {
  if (quick) return Sizes{256, 64, 64, 16, 4, 1024, 32, 0.0, 32u << 20, 16u << 20};
  return Sizes{16384, 1024, 1024, 64, 32, 100000, 1000, 0.3, 512u << 20, 512u << 20};
}

BenchReport run_bench(const BenchOptions& o, std::shared_ptr<OpenCLRuntime> rt, const OpenCLDeviceInfo& device) {
  const Sizes sz = Sizes::of(o.quick);
  BenchReport rep;
  rep.device = device;
  rep.date_utc = now_utc();
  rep.cpu = cpu_name();
  rep.host_threads = default_threads();
  rep.quick = o.quick;
  rep.repetitions = o.repetitions;
  rep.dir = o.dir;
  if (::getloadavg(rep.load, 3) != 3) rep.load[0] = rep.load[1] = rep.load[2] = 0;

  const Catalogue cat = default_catalogue();
  const AssetSet assets = build_assets(cat);
  auto kernels = make_opencl_backend(cat, assets, rt);
  auto reference = make_reference_backend(cat, assets);

  const std::vector<SpeedPath> chosen = chosen_paths(o.paths);
  for (const SpeedPath& p : chosen) {
    PathResult r;
    r.path = p;
    const bool features = p.kernel.images == 0;
    r.batch = features ? sz.features_batch : sz.images_batch;
    r.exact_batch = features ? sz.exact_features_batch : sz.exact_images_batch;
    r.reference_batch = sz.reference_batch;
    r.end_to_end_count = features ? sz.features_count : sz.images_count;
    for (Measure m : kMeasures)
      if (std::string why = why_not(p, m, device); !why.empty()) r.skipped[m] = why;
    rep.paths.push_back(std::move(r));
  }
  rep.fp64_note = fp64_note(chosen, device);

  int steps = 2;  // memory and disk
  for (const PathResult& r : rep.paths) steps += static_cast<int>(std::size(kMeasures) - r.skipped.size());
  Progress progress(o.progress, steps * o.repetitions);

  // Per path, made once: the batches, the outputs and the loop's tables.
  struct Work {
    SceneBatch batch{0}, mid{0}, small{0};  // make_batch's
    BatchOutput kernel, exact, loop, reference;
    std::unique_ptr<Loop> loop_impl;
    Plan exact_plan;
  };
  std::vector<Work> work(rep.paths.size());
  const Scratch scratch{fs::path(o.dir) / ("portalsim-bench-" + std::to_string(::getpid()))};
  std::error_code ec;
  fs::create_directories(scratch.dir, ec);
  if (ec) throw OutputError("--dir: cannot make " + scratch.dir.string() + ": " + ec.message());

  for (int k = 0; k < o.repetitions; ++k) {
    const std::string of = " (repetition " + std::to_string(k + 1) + " of " + std::to_string(o.repetitions) + ")";
    progress.step("memory write rate" + of);
    rep.memory_rates.push_back(memory_write_rate(sz.memory_bytes, rep.host_threads));
    progress.step("disk write rate in " + o.dir + of);
    const DiskRate d = disk_write_rate(o.dir, sz.disk_bytes);
    rep.disk_rates.push_back(d.bytes_per_s);
    rep.disk_direct = d.direct;
    for (size_t i = 0; i < rep.paths.size(); ++i) {
      PathResult& r = rep.paths[i];
      Work& w = work[i];
      const Plan& plan = r.path.kernel;
      auto runs = [&](Measure m) { return !r.skipped.count(m); };
      if (k == 0) {  // untimed first runs: kernel builds, tables, first-touch pages
        w.batch = make_batch(cat, r.batch);
        w.mid = make_batch(cat, r.exact_batch);
        w.small = make_batch(cat, r.reference_batch);
        kernels->run(w.batch, plan, w.kernel);
        r.output_bytes = output_bytes_per_scenario(w.kernel);
        w.exact_plan = plan;
        w.exact_plan.fidelity = tier_fidelity(Tier::exact);
        if (runs(Measure::exact)) kernels->run(w.mid, w.exact_plan, w.exact);
        if (runs(Measure::loop)) {
          w.loop_impl = std::make_unique<Loop>(cat, assets, r.path);
          prepare_output(w.loop, cat, plan, r.batch);
          w.loop_impl->run(w.batch, w.loop);
        }
        if (runs(Measure::reference)) reference->run(w.small, plan, w.reference);
      }
      const std::string name = r.path.key + ": ";
      progress.step(name + "kernel" + of);
      r.rates[Measure::kernel].push_back(
          rate_of(r.batch, sz.min_seconds, [&] { kernels->run(w.batch, plan, w.kernel); }));
      if (runs(Measure::exact)) {
        progress.step(name + "exact tier" + of);
        r.rates[Measure::exact].push_back(
            rate_of(r.exact_batch, sz.min_seconds, [&] { kernels->run(w.mid, w.exact_plan, w.exact); }));
      }
      if (runs(Measure::loop)) {
        progress.step(name + "plain loop" + of);
        r.rates[Measure::loop].push_back(rate_of(r.batch, sz.min_seconds, [&] { w.loop_impl->run(w.batch, w.loop); }));
      }
      if (runs(Measure::reference)) {
        progress.step(name + "fp64 reference" + of);
        r.rates[Measure::reference].push_back(
            rate_of(r.reference_batch, sz.min_seconds, [&] { reference->run(w.small, plan, w.reference); }));
      }
      if (runs(Measure::end_to_end)) {
        progress.step(name + "end to end" + of);
        RunSpec spec = r.path.spec;
        spec.count = r.end_to_end_count;
        const fs::path out = scratch.dir / (r.path.key + "-" + std::to_string(k));
        PipelineOptions opt;
        const auto t0 = Clock::now();
        run_pipeline(spec, cat, assets, *kernels, out.string(), opt);
        const double s = since(t0);
        r.rates[Measure::end_to_end].push_back(static_cast<double>(spec.count) / s);
        r.written_bytes = static_cast<double>(folder_bytes(out)) / static_cast<double>(spec.count);
        fs::remove_all(out, ec);
      }
    }
  }
  return rep;
}

}  // namespace portalsim::speed
