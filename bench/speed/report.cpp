#include "speed/report.h"

#include <cmath>
#include <cstdio>

namespace portalsim::speed {

using nlohmann::json;

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string percent(double share) { return share >= 0.1 ? fmt("%.0f%%", 100 * share) : fmt("%.1f%%", 100 * share); }

}  // namespace

std::string format_rate(double v) {
  if (v >= 1e6) return fmt("%.3gM/s", v / 1e6);
  if (v >= 1e3) return fmt("%.3gk/s", v / 1e3);
  return fmt("%.3g/s", v);
}

json report_json(const BenchReport& r) {
  const double memory = median(r.memory_rates), disk = median(r.disk_rates);
  json j;
  j["date"] = r.date_utc;
  j["device"] = {{"name", r.device.name},
                 {"type", r.device.type},
                 {"compute_units", r.device.compute_units},
                 {"fp64", r.device.fp64}};
  j["host"] = {{"cpu", r.cpu}, {"threads", r.host_threads}, {"load_average", {r.load[0], r.load[1], r.load[2]}}};
  j["quick"] = r.quick;
  j["repetitions"] = r.repetitions;
  j["memory"] = {{"write_bytes_per_s", memory}, {"repetitions", r.memory_rates}};
  j["disk"] = {
      {"dir", r.dir}, {"direct_io", r.disk_direct}, {"write_bytes_per_s", disk}, {"repetitions", r.disk_rates}};
  if (!r.fp64_note.empty()) j["fp64_note"] = r.fp64_note;
  j["paths"] = json::array();
  for (const PathResult& p : r.paths) {
    json jp;
    jp["key"] = p.path.key;
    jp["title"] = p.path.title;
    jp["batch"] = p.batch;
    jp["exact_batch"] = p.exact_batch;
    jp["reference_batch"] = p.reference_batch;
    jp["end_to_end_count"] = p.end_to_end_count;
    const auto loop = p.rates.find(Measure::loop);
    const double loop_rate = loop == p.rates.end() ? 0 : median(loop->second);
    for (Measure m : kMeasures) {
      json jm;
      if (auto why = p.skipped.find(m); why != p.skipped.end()) {
        jm["skipped"] = why->second;
      } else {
        const double rate = median(p.rates.at(m));
        jm["per_s"] = rate;
        jm["repetitions"] = p.rates.at(m);
        if (loop_rate > 0) jm["vs_loop"] = rate / loop_rate;
        if (m == Measure::kernel) {
          jm["bytes_per_scenario"] = p.output_bytes;
          jm["memory_share"] = rate * p.output_bytes / memory;
        }
        if (m == Measure::end_to_end) {
          jm["bytes_per_scenario"] = p.written_bytes;
          jm["disk_share"] = rate * p.written_bytes / disk;
        }
      }
      jp[measure_key(m)] = jm;
    }
    j["paths"].push_back(jp);
  }
  return j;
}

std::string report_text(const BenchReport& r) {
  const json j = report_json(r);
  std::string s = "portalsim bench on " + r.device.name + " (" + r.device.type + ", " +
                  std::to_string(r.device.compute_units) + " compute units, fp64 " + (r.device.fp64 ? "yes" : "no") +
                  ")\n" + r.date_utc + "; host: " + (r.cpu.empty() ? "?" : r.cpu) + ", " +
                  std::to_string(r.host_threads) + " threads; load average " + fmt("%.2f", r.load[0]) + " " +
                  fmt("%.2f", r.load[1]) + " " + fmt("%.2f", r.load[2]) + "; medians of " +
                  std::to_string(r.repetitions) + " repetitions" + (r.quick ? " (--quick: small batches)" : "") +
                  "\n\nScenarios/s, and in brackets the ratio to the plain loop (bench/baseline/):\n\n";
  s += "| path |";
  for (Measure m : kMeasures) s += std::string(" ") + measure_title(m) + " |";
  s += "\n|---|---|---|---|---|---|\n";
  for (const json& p : j["paths"]) {
    s += "| " + p["title"].get<std::string>() + " |";
    for (Measure m : kMeasures) {
      const json& c = p[measure_key(m)];
      if (c.contains("skipped"))
        s += " — |";
      else {
        s += " ";
        s += format_rate(c["per_s"].get<double>());
        if (c.contains("vs_loop")) s += " (" + fmt("%.3gx", c["vs_loop"].get<double>()) + ")";
        s += " |";
      }
    }
    s += "\n";
  }
  const double memory = j["memory"]["write_bytes_per_s"], disk = j["disk"]["write_bytes_per_s"];
  s += "\nMemory takes fresh bytes at " + fmt("%.1f GB/s", memory / 1e9) + " (memset of " +
       std::to_string(Sizes::of(r.quick).memory_bytes >> 20) + " MiB on " + std::to_string(r.host_threads) +
       " threads); " + r.dir + " at " + fmt("%.2f GB/s", disk / 1e9) + " (" +
       (r.disk_direct ? "direct I/O, as dd oflag=direct" : "written, then fsync: no direct I/O there") +
       "). What the run reached of each:\n\n";
  s += "| path | kernel output per scenario | share of memory | written per scenario, end to end | share of disk |\n";
  s += "|---|---|---|---|---|\n";
  for (const json& p : j["paths"]) {
    const json &k = p["kernel"], &e = p["end_to_end"];
    s += "| " + p["key"].get<std::string>() + " | " + fmt("%.0f B", k["bytes_per_scenario"].get<double>()) + " | " +
         percent(k["memory_share"].get<double>()) + " | ";
    if (e.contains("skipped"))
      s += "— | — |\n";
    else
      s += fmt("%.0f B", e["bytes_per_scenario"].get<double>()) + " | " + percent(e["disk_share"].get<double>()) +
           " |\n";
  }
  const Sizes sz = Sizes::of(r.quick);
  s += "\nKernel and plain loop: batches of " + std::to_string(sz.features_batch) + " (features) and " +
       std::to_string(sz.images_batch) + " (images); exact tier: " + std::to_string(sz.exact_features_batch) + " and " +
       std::to_string(sz.exact_images_batch) + "; fp64 reference: " + std::to_string(sz.reference_batch) +
       "; end to end: portalsim generate of " + std::to_string(sz.features_count) + " (features) and " +
       std::to_string(sz.images_count) + " (images) scenarios into " + r.dir +
       ". The physics model has no plain loop.\n";
  bool skipped = false;
  for (const PathResult& p : r.paths)
    for (const auto& [m, why] : p.skipped)
      if (m != Measure::loop || p.path.has_loop) skipped = true;
  if (!r.fp64_note.empty())
    s += "\n" + r.fp64_note + "\n";
  else if (skipped)
    s += "\nSome measurements did not run: --json says why.\n";
  return s;
}

}  // namespace portalsim::speed
