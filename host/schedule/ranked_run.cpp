#include "schedule/ranked_run.h"

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <thread>

#include "base/error.h"
#include "schedule/join.h"
#include "schedule/scenario_source.h"
#include "sink/output_folder.h"
#include "sink/sink_kinds.h"
#include "sink/staging.h"

namespace portalsim {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

fs::path parts_dir(const std::string& dir) { return fs::path(dir) / kStateDir / "parts"; }

fs::path part_dir(const std::string& dir, uint64_t p, uint64_t k) {
  return parts_dir(dir) / (std::to_string(p) + "-of-" + std::to_string(k));
}

json read_json(const fs::path& p) { return json::parse(read_state_file(p.string())); }

// Scenarios a part has written so far, from its checkpoint or manifest (0 when neither
// can be read yet).
uint64_t part_done(const fs::path& part) {
  std::error_code ec;
  try {
    if (fs::exists(part / "manifest.json", ec)) return read_json(part / "manifest.json").at("count").get<uint64_t>();
    const fs::path c = part / kStateDir / "checkpoint.json";
    if (fs::exists(c, ec)) {
      const json j = read_json(c);
      return j.at("next").get<uint64_t>() - j.at("identity").at("shard").at("begin").get<uint64_t>();
    }
  } catch (const std::exception&) {
    // Being replaced as we read it: count it next time.
  }
  return 0;
}

// Rank 0's view of the whole job, from the parts' checkpoints on the shared filesystem.
class JobProgress {
 public:
  JobProgress(const std::string& dir, uint64_t parts, uint64_t total)
      : dir_(dir), parts_(parts), total_(total), tty_(::isatty(STDERR_FILENO)), thread_([this] { loop(); }) {}
  ~JobProgress() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
    draw();
    std::fprintf(stderr, "\n");
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(m_);
    while (!cv_.wait_for(lock, std::chrono::seconds(tty_ ? 1 : 10), [&] { return stop_; })) draw();
  }
  void draw() {
    uint64_t done = 0;
    for (uint64_t p = 0; p < parts_; ++p) done += part_done(part_dir(dir_, p, parts_));
    const double s = std::chrono::duration<double>(Clock::now() - t0_).count(), rate = s > 0 ? done / s : 0;
    const double eta = rate > 0 ? (total_ - done) / rate : 0;
    std::fprintf(stderr, "%s%llu/%llu scenarios (%.1f%%) in %llu parts, %.0f scenarios/s, ETA %02d:%02d:%02d%s",
                 tty_ ? "\r" : "", static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_),
                 total_ ? 100.0 * done / total_ : 100.0, static_cast<unsigned long long>(parts_), rate,
                 static_cast<int>(eta / 3600), static_cast<int>(eta / 60) % 60, static_cast<int>(eta) % 60,
                 tty_ ? " " : "\n");
    std::fflush(stderr);
  }
  std::string dir_;
  uint64_t parts_, total_;
  bool tty_;
  Clock::time_point t0_ = Clock::now();
  std::mutex m_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace

bool has_ranked_parts(const std::string& dir) {
  std::error_code ec;
  return fs::exists(parts_dir(dir) / "job.json", ec);
}

PipelineResult run_ranked(const RunSpec& spec, const Catalogue& cat, const AssetSet& assets, Backend& backend,
                          const std::string& dir, const PipelineOptions& opt, Ranks& ranks) {
  const auto t0 = Clock::now();
  if (opt.shards != 1) throw InputError("--shard: not with an MPI launch; the ranks split the range among them");
  // The ranks' parts are joined as merge joins shards: an output merge cannot join is refused.
  const SinkRequest req = sink_request(spec, run_plan(spec, cat), nullptr);
  for (const SinkKind* k : sink_kinds())
    if (k->wanted(req) && k->join && k->join(k->name) == JoinAs::refused)
      throw InputError(std::string(k->flag) + ": not with an MPI launch: " + std::string(k->refusal) +
                       "; run on one rank");
  const fs::path out(dir), job = parts_dir(dir) / "job.json";
  PipelineResult res;
  res.end = spec.scenarios.empty() ? spec.count : 0;

  // Rank 0 checks the folder, holds its lock for the job and fixes the split.
  std::optional<FolderLock> lock;
  uint64_t parts = 0;
  bool complete = false;
  ranks.together([&] {
    if (ranks.rank() != 0) return;
    std::error_code ec;
    if (holds_finished_run(spec, cat, dir, opt.resume)) {
      complete = true;
      return;
    }
    const FolderState state = output_folder_state(dir);
    if (state == FolderState::missing) {
      fs::create_directories(out, ec);
      if (ec) throw OutputError(dir + ": cannot create the output folder: " + ec.message());
    }
    lock.emplace(dir);
    if (fs::exists(job, ec)) {
      if (!opt.resume)
        throw OutputError(dir +
                          ": holds an interrupted run (.portalsim/parts); use --resume to finish it, with any "
                          "number of ranks, or choose a new folder");
      parts = read_json(job).at("parts").get<uint64_t>();
      if (parts < 1) throw OutputError(job.string() + ": no parts");
    } else {
      if (output_folder_state(dir) == FolderState::has_files)
        throw OutputError(dir + (opt.resume ? ": holds no interrupted run to resume; choose a new folder"
                                            : ": is not empty; choose a new folder"));
      fs::create_directories(parts_dir(dir), ec);
      if (ec) throw OutputError(parts_dir(dir).string() + ": cannot create: " + ec.message());
      parts = static_cast<uint64_t>(ranks.size());
      write_text_atomic(job.string(), json{{"parts", parts}}.dump() + "\n");
    }
  });
  const std::vector<std::string> shared = ranks.all_gather(complete ? "complete" : std::to_string(parts));
  if (shared[0] == "complete") {
    res.already_complete = true;
    return res;
  }
  parts = std::stoull(shared[0]);

  // Each rank makes its parts, one after another.
  std::optional<JobProgress> progress;
  if (opt.progress && ranks.rank() == 0 && spec.scenarios.empty()) progress.emplace(dir, parts, spec.count);
  PipelineResult mine;
  ranks.together([&] {
    for (uint64_t p = static_cast<uint64_t>(ranks.rank()); p < parts; p += static_cast<uint64_t>(ranks.size())) {
      PipelineOptions o = opt;
      o.shard = p;
      o.shards = parts;
      o.resume = true;  // a part folder is new, interrupted or finished
      o.progress = false;
      const PipelineResult r = run_pipeline(spec, cat, assets, backend, part_dir(dir, p, parts).string(), o);
      mine.done += r.done;
      mine.compute_seconds += r.compute_seconds;
      mine.write_wait_seconds += r.write_wait_seconds;
      mine.batch = r.batch;
      if (r.interrupted) {
        mine.interrupted = true;
        break;
      }
    }
  });
  progress.reset();
  const std::vector<std::string> each = ranks.all_gather(json{
      {"done", mine.done},
      {"interrupted", mine.interrupted},
      {"compute", mine.compute_seconds},
      {"wait", mine.write_wait_seconds}}.dump());
  res.batch = mine.batch;
  for (const std::string& e : each) {
    const json j = json::parse(e);
    res.done += j["done"].get<uint64_t>();
    res.interrupted = res.interrupted || j["interrupted"].get<bool>();
    res.compute_seconds = std::max(res.compute_seconds, j["compute"].get<double>());
    res.write_wait_seconds = std::max(res.write_wait_seconds, j["wait"].get<double>());
  }
  if (res.interrupted) {
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return res;
  }

  // Join the parts into the folder, then drop them.
  std::vector<std::string> dirs;
  for (uint64_t p = 0; p < parts; ++p) dirs.push_back(part_dir(dir, p, parts).string());
  std::vector<Part> joined;
  ranks.together([&] { joined = read_parts(dirs); });
  const JoinResult j = join_parts(joined, dir, ranks);
  ranks.together([&] {
    if (ranks.rank() != 0) return;
    std::error_code ec;
    fs::remove_all(parts_dir(dir), ec);
    if (ec) throw OutputError(parts_dir(dir).string() + ": cannot remove the joined parts: " + ec.message());
  });
  res.begin = 0;
  res.end = j.count;
  res.positive = j.positive;
  res.negative = j.negative;
  res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return res;
}

}  // namespace portalsim
