#include "schedule/pipeline.h"

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "base/error.h"
#include "base/parallel.h"
#include "base/recycler.h"
#include "base/sizes.h"
#include "schedule/body_pages.h"
#include "schedule/dataset_card.h"
#include "schedule/identity.h"
#include "schedule/run_state.h"
#include "schedule/scenario_source.h"
#include "sink/coco.h"
#include "sink/h5_file.h"
#include "sink/output_folder.h"
#include "sink/sinks.h"
#include "sink/staging.h"
#include "sink/tensors.h"

namespace portalsim {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Job {
  SceneBatch scenes{0};  // ScenarioSource::fill gives it the catalogue's stride
  BatchOutput out;
};

// One-slot hand-over between the compute thread and the writer thread.
class Handover {
 public:
  void put(std::unique_ptr<Job> j) {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait(lock, [&] { return !slot_ || failed_; });
    if (failed_) return;
    slot_ = std::move(j);
    cv_.notify_all();
  }
  std::unique_ptr<Job> take() {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait(lock, [&] { return slot_ || closed_; });
    std::unique_ptr<Job> j = std::move(slot_);
    cv_.notify_all();
    return j;
  }
  void close() {
    std::lock_guard<std::mutex> lock(m_);
    closed_ = true;
    cv_.notify_all();
  }
  void fail() {
    std::lock_guard<std::mutex> lock(m_);
    failed_ = true;
    cv_.notify_all();
  }
  bool failed() {
    std::lock_guard<std::mutex> lock(m_);
    return failed_;
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::unique_ptr<Job> slot_;
  bool closed_ = false, failed_ = false;
};

void draw_progress(uint64_t done, uint64_t total, double seconds) {
  const double rate = seconds > 0 ? done / seconds : 0;
  const double eta = rate > 0 ? (total - done) / rate : 0;
  const int width = 30, filled = total ? static_cast<int>(width * done / total) : width;
  std::fprintf(stderr, "\r[%s%s] %5.1f%% %llu/%llu  %.0f scenarios/s  ETA %02d:%02d:%02d ",
               std::string(filled, '=').c_str(), std::string(width - filled, ' ').c_str(),
               total ? 100.0 * done / total : 100.0, static_cast<unsigned long long>(done),
               static_cast<unsigned long long>(total), rate, static_cast<int>(eta / 3600),
               static_cast<int>(eta / 60) % 60, static_cast<int>(eta) % 60);
  std::fflush(stderr);
}

// What a run is, for its checkpoint, its manifest and a later --resume or merge.
json run_identity(const RunSpec& spec, const Catalogue& cat, uint64_t total, const PipelineOptions& opt,
                  const PipelineResult& res) {
  json identity;
  identity["portalsim"] = PORTALSIM_VERSION;
  // The portal it describes, so that the dataset card can say what the data hold.
  json views = json::array();
  for (const Sensor& v : cat.sensors) {
    json view{{"name", v.name}, {"camera", camera_name(v.camera)}, {"side", side_name(v.side)}, {"pooled", v.pooled}};
    // A camera of its own (the physics model's knobs it keeps whatever the run's).
    if (v.netd) view["netd"] = *v.netd;
    if (v.raw) view["raw"] = std::to_string((*v.raw)[0]) + "x" + std::to_string((*v.raw)[1]);
    views.push_back(std::move(view));
  }
  identity["catalogue"] = {{"source", cat.source},
                           {"hash", cat.hash},
                           {"portal", {{"views", views}, {"regions", cat.region_count()}, {"zones", cat.zones}}}};
  identity["spec"] = spec.to_json();
  if (!spec.scenarios.empty()) identity["spec"]["scenarios_count"] = total;
  identity["shard"] = {{"index", opt.shard}, {"count", opt.shards}, {"begin", res.begin}, {"end", res.end}};
  return identity;
}

struct FolderStart {
  bool complete = false;  // a finished run of the same identity: --resume has nothing to do
  bool resuming = false;  // an interrupted run of the same identity, to go on from `checkpoint`
  json checkpoint;
};

// Whether `dir` holds a finished run (a manifest.json). Throws when it does without
// `resume`, or when that run's identity differs from `identity`, naming every key.
bool finished_run_here(const std::string& dir, const json& identity, bool resume) {
  const fs::path manifest_path = fs::path(dir) / "manifest.json";
  std::error_code ec;
  if (!fs::exists(manifest_path, ec)) return false;
  if (!resume)
    throw OutputError(dir +
                      ": is not empty: it holds a finished run (manifest.json); choose a new folder (--resume "
                      "only checks that it is complete)");
  json manifest;
  try {
    manifest = parse_manifest(read_state_file(manifest_path.string()), manifest_path.string());
  } catch (const InputError& e) {  // the folder is the run's output
    throw OutputError(e.what());
  }
  json was = json::object();
  for (const auto& [k, v] : identity.items()) was[k] = manifest.value(k, json());
  if (const std::string diff = differing_keys(was, identity, {"in the folder", "now"}); !diff.empty())
    throw InputError("--resume: " + dir + " holds a finished run that differs in " + diff +
                     "; give the same parameters, or another folder");
  return true;
}

// What the output folder holds, read with its lock held: new (or a run stopped before its
// first checkpoint, whose files go), an interrupted run to resume, or a finished one.
// Throws when the folder holds anything else, or a run with another identity.
FolderStart examine_folder(const std::string& dir, const json& identity, bool resume) {
  const fs::path out(dir), checkpoint_path = out / kStateDir / "checkpoint.json",
                           started_path = out / kStateDir / "started";
  std::error_code ec;
  FolderStart start;
  if (finished_run_here(dir, identity, resume)) {
    // Complete; a crash after the manifest was written may have left the checkpoint.
    fs::remove(checkpoint_path, ec);
    fs::remove(started_path, ec);
    start.complete = true;
    return start;
  }
  if (resume && fs::exists(checkpoint_path, ec)) {
    start.checkpoint = parse_checkpoint(read_state_file(checkpoint_path.string()), checkpoint_path.string());
    if (const std::string diff =
            differing_keys(start.checkpoint.value("identity", json::object()), identity, {"in the folder", "now"});
        !diff.empty())
      throw InputError("--resume: " + dir + " was made by a run that differs in " + diff +
                       "; give the same parameters, or another folder");
    start.resuming = true;
  } else if (fs::exists(started_path, ec) && !fs::exists(checkpoint_path, ec)) {
    // A run stopped before its first checkpoint: all that is here is its own; start again.
    for (const auto& entry : fs::directory_iterator(out, ec))
      if (entry.path().filename() != kStateDir) fs::remove_all(entry.path(), ec);
  } else if (output_folder_state(dir) == FolderState::has_files || fs::exists(checkpoint_path, ec)) {
    throw OutputError(dir + (resume ? ": holds no interrupted run to resume (no .portalsim/checkpoint.json); "
                                      "choose a new folder"
                                    : ": is not empty; use --resume to continue an interrupted run there, or "
                                      "choose a new folder"));
  }
  return start;
}

// Generates, computes and writes scenarios [written, res.end) batch by batch: the main
// thread generates and computes batch k while a writer thread writes batch k-1, records
// `checkpoint(next)` and advances `written` (which an error leaves where it stood).
// Per-scenario bodies (`pages`): a batch never crosses a page of bodies, and runs on its page's backend.
void run_batches(const ScenarioSource& source, const Plan& plan, Backend& backend, BodyPages* pages,
                 std::vector<std::unique_ptr<Sink>>& sinks, unsigned threads, const PipelineOptions& opt,
                 const std::function<void(uint64_t)>& checkpoint, PipelineResult& res, Clock::time_point t0,
                 std::atomic<uint64_t>& written) {
  const uint64_t first = written;
  Handover hand;
  Recycler<Job> jobs;  // three jobs at most exist
  std::exception_ptr writer_error;
  std::thread writer([&] {
    try {
      while (std::unique_ptr<Job> job = hand.take()) {
        for (auto& s : sinks) s->write(job->scenes, job->out);
        for (uint8_t l : job->scenes.label) (l == 1 ? res.positive : res.negative)++;
        const uint64_t next = job->scenes.first_index + job->scenes.size();
        checkpoint(next);
        written = next;
        jobs.give(std::move(job));
      }
    } catch (...) {
      writer_error = std::current_exception();
      hand.fail();
    }
  });

  std::exception_ptr compute_error;
  double last_draw = -1;
  try {
    for (uint64_t at = first, n = 0; at < res.end; at += n) {
      n = std::min<uint64_t>(res.batch, res.end - at);
      if (pages) n = std::min<uint64_t>(n, (body_page(at) + 1) * kBodyPage - at);
      if (opt.stop && *opt.stop) {
        res.interrupted = true;
        break;
      }
      if (hand.failed()) break;
      std::unique_ptr<Job> job = jobs.take();
      SceneBatch& b = job->scenes;
      source.fill(at, static_cast<size_t>(n), threads, b);
      const auto tc = Clock::now();
      (pages ? pages->backend_for(body_page(at), b) : backend).run(b, plan, job->out);
      res.compute_seconds += since(tc);
      const auto tw = Clock::now();
      hand.put(std::move(job));
      res.write_wait_seconds += since(tw);
      if (opt.progress && since(t0) - last_draw > 0.2) {
        last_draw = since(t0);
        draw_progress(written - res.begin, res.end - res.begin, since(t0));
      }
    }
  } catch (...) {
    compute_error = std::current_exception();
  }
  hand.close();
  writer.join();
  if (opt.progress) {
    draw_progress(written - res.begin, res.end - res.begin, since(t0));
    std::fprintf(stderr, "\n");
  }
  if (compute_error) std::rethrow_exception(compute_error);
  if (writer_error) std::rethrow_exception(writer_error);
}

// A finished run: every file gets its final name, then the dataset card, then the manifest.
void write_manifest(const std::string& dir, std::vector<std::unique_ptr<Sink>>& sinks, const json& identity,
                    const PipelineResult& res, bool image_folders) {
  std::vector<FileState> outputs;
  for (auto& s : sinks) {
    s->finish();  // before files(): data.h5 exists only once finished
    for (const FileState& f : s->files()) outputs.push_back(f);
  }
  const json manifest = run_manifest(identity, res.end - res.begin, res.positive, res.negative, outputs, image_folders);
  write_dataset_card(dir, manifest);  // before the manifest, which marks the folder finished
  write_text_atomic((fs::path(dir) / "manifest.json").string(), manifest.dump(2) + "\n");
}

}  // namespace

// About 16 MiB of outputs: the batch being written and the next being computed fit in a
// 32 MiB last-level cache together, so the writer mostly reads the kernels' output from the
// cache rather than from memory (docs/guide/deep-learning.md).
size_t default_batch(const Plan& plan, const Catalogue& cat, const Backend& backend) {
  size_t bytes = 64 + static_cast<size_t>(cat.zones);
  for (int k : backend.rendered_views(plan)) bytes += cat.sensors[k].pixels();  // none where a features path runs
  if (plan.features) bytes += sizeof(float) * FeatureLayout::of(cat, plan.model.block).image_features();
  // A multiple of data.h5's chunk rows: a batch ends where a chunk does, so no piece of it
  // waits in memory for the next batch before the file's hash can take it (file_order_hash.h).
  const size_t rows = std::clamp<size_t>(kIoPieceBytes / bytes, kH5ChunkRows, 16384);
  return (rows + kH5ChunkRows / 2) / kH5ChunkRows * kH5ChunkRows;
}

bool holds_finished_run(const RunSpec& spec, const Catalogue& cat, const std::string& dir, bool resume) {
  std::error_code ec;
  if (!fs::exists(fs::path(dir) / "manifest.json", ec)) return false;
  PipelineResult whole;
  whole.end = ScenarioSource(spec, cat).total();
  return finished_run_here(dir, run_identity(spec, cat, whole.end, PipelineOptions{}, whole), resume);
}

PipelineResult run_pipeline(const RunSpec& spec, const Catalogue& cat, const AssetSet& assets, Backend& backend,
                            const std::string& dir, const PipelineOptions& opt) {
  const auto t0 = Clock::now();
  PipelineResult res;
  const ScenarioSource source(spec, cat);
  if (opt.shards < 1 || opt.shard >= opt.shards) throw InputError("--shard: expected i/k with 0 <= i < k");
  res.begin = source.total() * opt.shard / opt.shards;
  res.end = source.total() * (opt.shard + 1) / opt.shards;

  const Plan plan = run_plan(spec, cat);
  res.batch = opt.batch ? opt.batch : default_batch(plan, cat, backend);
  std::optional<BodyPages> pages;
  if (spec.per_scenario_bodies()) {
    pages.emplace(cat, assets, backend, spec.bodies_seed());
    res.batch = std::min<size_t>(res.batch, kBodyPage);
  }
  const unsigned threads = opt.threads ? opt.threads : default_threads();
  const json identity = run_identity(spec, cat, source.total(), opt, res);

  // The output folder: the lock is taken before anything in it is read or changed.
  const fs::path out(dir), state_dir = out / kStateDir, checkpoint_path = state_dir / "checkpoint.json",
                           started_path = state_dir / "started";
  std::error_code ec;
  const bool created_dir = output_folder_state(dir) == FolderState::missing;
  if (created_dir) {
    fs::create_directories(out, ec);
    if (ec) throw OutputError(dir + ": cannot create the output folder: " + ec.message());
  }
  const FolderLock lock(dir);
  const FolderStart start = examine_folder(dir, identity, opt.resume);
  if (start.complete) {
    res.already_complete = true;
    return res;
  }
  // A fresh run that fails before any batch is written leaves nothing of its own
  // behind; the folder was empty, or is one this run made.
  struct Cleanup {
    fs::path dir;
    bool created, armed;
    ~Cleanup() {
      if (!armed) return;
      std::error_code e;
      if (created) {
        fs::remove_all(dir, e);
      } else {
        for (const auto& entry : fs::directory_iterator(dir, e)) fs::remove_all(entry.path(), e);
      }
    }
  } cleanup{out, created_dir, !start.resuming};
  if (!start.resuming) write_text_atomic(started_path.string(), identity.dump() + "\n");
  if (::access(state_dir.c_str(), W_OK) != 0) throw OutputError(dir + ": the output folder is not writable");

  const uint64_t first = start.resuming ? start.checkpoint["next"].get<uint64_t>() : res.begin;
  if (first < res.begin || first > res.end)
    throw OutputError(checkpoint_path.string() + ": next: " + std::to_string(first) + " is not in this run's [" +
                      std::to_string(res.begin) + ", " + std::to_string(res.end) + "]; the run cannot be resumed");
  // A list's rows are read as the run goes; read them all once first, so that a bad row
  // fails the run before it writes anything.
  source.check(first, res.end, threads);
  if (start.resuming) {
    res.positive = start.checkpoint["positive"].get<uint64_t>();
    res.negative = start.checkpoint["negative"].get<uint64_t>();
  }
  SinkContext ctx = plan_sink_context(plan, cat, assets, threads, spec.image_format);
  ctx.dir = dir;
  ctx.png_level = spec.png_level;
  ctx.rows = res.end - res.begin;
  ctx.done = first - res.begin;
  std::map<std::string, FileState> saved;
  if (start.resuming)
    for (const json& f : start.checkpoint["files"])
      saved[f["name"]] = FileState{f["name"], f["bytes"].get<uint64_t>(), f["xxh3"].get<uint64_t>()};
  Sinks sinks = open_sinks(sink_request(spec, plan, source.rule(), identity), ctx,
                           SinkStart{start.resuming ? &saved : nullptr, first});

  const auto checkpoint = [&](uint64_t next) {
    json c;
    c["identity"] = identity;
    c["next"] = next;
    c["positive"] = res.positive;
    c["negative"] = res.negative;
    c["files"] = json::array();
    for (const auto& s : sinks)
      for (const FileState& f : s->files())
        c["files"].push_back({{"name", f.name}, {"bytes", f.bytes}, {"xxh3", f.xxh3}});
    write_text_atomic(checkpoint_path.string(), c.dump(1) + "\n");
  };
  if (!start.resuming) {
    checkpoint(first);
    fs::remove(started_path, ec);
  }

  std::atomic<uint64_t> written{first};
  std::exception_ptr error;
  try {
    run_batches(source, plan, backend, pages ? &*pages : nullptr, sinks, threads, opt, checkpoint, res, t0, written);
  } catch (...) {
    error = std::current_exception();
  }
  if (written > first || res.end == first) cleanup.armed = false;  // progress worth resuming
  if (error) std::rethrow_exception(error);
  res.done = written - first;
  res.seconds = since(t0);
  if (res.interrupted) return res;

  write_manifest(dir, sinks, identity, res, plan.images && !spec.image_tensors());
  fs::remove_all(state_dir, ec);
  res.seconds = since(t0);  // with the finishing work (data.h5 is built there)
  return res;
}

}  // namespace portalsim
