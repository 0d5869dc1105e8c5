#include "schedule/pipeline.h"

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <thread>

#include "scene/error.h"
#include "schedule/parallel.h"
#include "sink/sinks.h"
#include "sink/staging.h"

namespace portalsim {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Job {
  SceneBatch scenes;
  BatchOutput out;
};

// One-slot hand-over between the compute thread and the writer thread, plus the pool
// of finished jobs whose buffers the next batch reuses (three jobs at most exist).
class Handover {
 public:
  std::unique_ptr<Job> recycled() {
    std::lock_guard<std::mutex> lock(m_);
    if (free_.empty()) return std::make_unique<Job>();
    std::unique_ptr<Job> j = std::move(free_.back());
    free_.pop_back();
    return j;
  }
  void recycle(std::unique_ptr<Job> j) {
    std::lock_guard<std::mutex> lock(m_);
    free_.push_back(std::move(j));
  }
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
  std::vector<std::unique_ptr<Job>> free_;
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

}  // namespace

size_t default_batch(const Plan& plan, const Catalogue& cat) {
  size_t bytes = 64 + kZones;
  for (size_t k = 0; k < cat.sensors.size(); ++k)
    if (plan.renders(cat.sensors[k], static_cast<int>(k))) bytes += cat.sensors[k].pixels();
  if (plan.sparse_features()) bytes = 64 + kZones;  // no images, on the device either
  if (plan.features) bytes += sizeof(float) * FeatureLayout::of(cat, plan.model.block).image_features();
  return std::clamp<size_t>((64u << 20) / bytes, 64, 16384);
}

PipelineResult run_pipeline(const RunSpec& spec, cli::Session& session, const std::string& dir,
                            const PipelineOptions& opt) {
  const auto t0 = Clock::now();
  const Catalogue& cat = session.catalogue;
  PipelineResult res;

  // The scenario source.
  std::optional<Generator> generator;
  std::vector<Scenario> listed;
  std::optional<ThreatRule> rule;
  uint64_t total = spec.count;
  if (!spec.scenarios.empty()) {
    listed = read_scenario_file(cat, spec.scenarios);
    total = listed.size();
    if (!spec.rule.empty()) rule.emplace(cat, spec.rule, "--rule");
  } else {
    generator.emplace(cat, generator_spec(spec, cat), spec.seed);
  }
  if (opt.shards < 1 || opt.shard >= opt.shards) throw InputError("--shard: expected i/k with 0 <= i < k");
  res.begin = total * opt.shard / opt.shards;
  res.end = total * (opt.shard + 1) / opt.shards;

  Plan plan;
  plan.features = spec.wants_features();
  plan.metal = true;
  plan.images = spec.wants_images() ? kAllViews : 0;
  plan.model = spec.model;
  plan.model.seed = spec.seed;
  plan.fidelity = spec.fidelity();
  validate(plan, cat);
  res.batch = opt.batch ? opt.batch : default_batch(plan, cat);
  const unsigned threads = opt.threads ? opt.threads : default_threads();

  json identity;
  identity["portalsim"] = PORTALSIM_VERSION;
  identity["catalogue"] = {{"source", cat.source}, {"hash", cat.hash}};
  identity["spec"] = spec.to_json();
  if (!spec.scenarios.empty()) identity["spec"]["scenarios_count"] = total;
  identity["shard"] = {{"index", opt.shard}, {"count", opt.shards}, {"begin", res.begin}, {"end", res.end}};

  // The output folder: new, or an interrupted run of the same identity to resume.
  const fs::path out(dir), state_dir = out / ".portalsim", checkpoint_path = state_dir / "checkpoint.json";
  std::error_code ec;
  json checkpoint;
  bool resuming = false;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) throw OutputError(dir + ": exists and is not a folder");
  if (opt.resume && fs::exists(out / "manifest.json", ec)) {
    // Complete; a crash after the manifest was written may have left the state folder.
    fs::remove_all(state_dir, ec);
    res.already_complete = true;
    return res;
  }
  if (opt.resume && fs::exists(checkpoint_path, ec)) {
    try {
      checkpoint = json::parse(read_file(checkpoint_path));
    } catch (const json::exception& e) {
      throw OutputError(checkpoint_path.string() + ": unreadable checkpoint: " + e.what());
    }
    if (checkpoint.value("identity", json()) != identity) {
      // Name the first differing entry, with both values.
      std::string what = "identity";
      const json was = checkpoint.value("identity", json::object());
      for (const std::string k : {"spec", "catalogue", "shard", "portalsim"}) {  // the likeliest cause first
        const json& v = identity[k];
        const json old = was.value(k, json());
        if (old == v) continue;
        what = k + " (" + old.dump() + " there, " + v.dump() + " now)";
        if (v.is_object() && old.is_object())
          for (auto& [k2, v2] : v.items())
            if (old.value(k2, json()) != v2) {
              what = k + "." + k2 + " (" + old.value(k2, json()).dump() + " there, " + v2.dump() + " now)";
              break;
            }
        break;
      }
      throw InputError("--resume: " + dir + " was made by a different run: " + what +
                       "; give the same spec, or another folder");
    }
    resuming = true;
  } else if (opt.resume && fs::exists(out, ec) && !fs::is_empty(out, ec)) {
    throw OutputError(dir +
                      ": holds no interrupted run to resume (no .portalsim/checkpoint.json); "
                      "choose a new folder");
  } else if (fs::exists(out, ec) && !fs::is_empty(out, ec)) {
    throw OutputError(dir +
                      ": is not empty; use --resume to continue an interrupted run there, or choose a new folder");
  }
  const bool created_dir = !fs::exists(out, ec);
  fs::create_directories(state_dir, ec);
  if (ec) throw OutputError(dir + ": cannot create the output folder: " + ec.message());
  // A fresh run that fails before any batch is written leaves nothing behind.
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
  } cleanup{out, created_dir, !resuming};
  if (::access(state_dir.c_str(), W_OK) != 0) throw OutputError(dir + ": the output folder is not writable");

  const uint64_t start = resuming ? checkpoint["next"].get<uint64_t>() : res.begin;
  if (resuming) {
    res.positive = checkpoint["positive"].get<uint64_t>();
    res.negative = checkpoint["negative"].get<uint64_t>();
  }

  // Sinks, each continuing from its checkpointed state on resume.
  SinkContext ctx;
  ctx.dir = dir;
  ctx.cat = &cat;
  ctx.assets = &session.assets;
  ctx.layout = FeatureLayout::of(cat, plan.model.block);
  ctx.rows = res.end - res.begin;
  ctx.threads = threads;
  ctx.image_format = spec.image_format;
  std::map<std::string, FileState> saved;
  if (resuming)
    for (const json& f : checkpoint["files"])
      saved[f["name"]] = FileState{f["name"], f["bytes"].get<uint64_t>(), f["xxh3"].get<uint64_t>()};
  const auto resume_state = [&](const std::string& name) -> const FileState* {
    if (!resuming) return nullptr;
    auto it = saved.find(name);
    if (it == saved.end()) throw OutputError(checkpoint_path.string() + ": no state for " + name);
    return &it->second;
  };
  std::vector<std::unique_ptr<Sink>> sinks;
  sinks.push_back(make_scenario_list_sink(ctx, resume_state("scenarios.csv")));
  if (plan.features)
    for (const std::string& f : spec.formats) sinks.push_back(make_table_sink(f, ctx, resume_state("features." + f)));
  if (plan.images) sinks.push_back(make_image_sink(ctx, resuming, start));

  const auto save_checkpoint = [&](uint64_t next) {
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
  if (!resuming) save_checkpoint(start);

  // Writer thread: sinks, then the checkpoint, batch after batch.
  Handover hand;
  std::exception_ptr writer_error;
  std::atomic<uint64_t> written{start};
  std::thread writer([&] {
    try {
      while (std::unique_ptr<Job> job = hand.take()) {
        for (auto& s : sinks) s->write(job->scenes, job->out);
        for (uint8_t l : job->scenes.label) (l == 1 ? res.positive : res.negative)++;
        const uint64_t next = job->scenes.first_index + job->scenes.size();
        save_checkpoint(next);
        written = next;
        hand.recycle(std::move(job));
      }
    } catch (...) {
      writer_error = std::current_exception();
      hand.fail();
    }
  });

  std::exception_ptr compute_error;
  double last_draw = -1;
  try {
    for (uint64_t first = start; first < res.end; first += res.batch) {
      if (opt.stop && *opt.stop) {
        res.interrupted = true;
        break;
      }
      if (hand.failed()) break;
      std::unique_ptr<Job> job = hand.recycled();
      const size_t n = static_cast<size_t>(std::min<uint64_t>(res.batch, res.end - first));
      SceneBatch& b = job->scenes;
      b.first_index = first;
      b.subject.resize(n);
      b.objects.resize(n * kRegions);
      b.label.resize(n);
      parallel_for(n, n >= 1024 ? threads : 1, [&](size_t lo, size_t hi) {
        for (size_t i = lo; i < hi; ++i) {
          Scenario s = generator ? (*generator)(first + i) : listed[first + i];
          if (!generator && s.label < 0) s.label = rule && (*rule)(s) ? 1 : 0;
          b.subject[i] = static_cast<uint8_t>(s.subject);
          std::copy(s.objects.begin(), s.objects.end(), b.objects.begin() + i * kRegions);
          b.label[i] = static_cast<uint8_t>(s.label);
        }
      });
      const auto tc = Clock::now();
      session.backend->run(b, plan, job->out);
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
  if (written > start || res.end == start) cleanup.armed = false;  // progress worth resuming
  if (compute_error) std::rethrow_exception(compute_error);
  if (writer_error) std::rethrow_exception(writer_error);
  res.done = written - start;
  res.seconds = since(t0);
  if (res.interrupted) return res;

  // Complete: final names, then the manifest, then the checkpoint goes.
  json manifest = identity;
  manifest["count"] = res.end - res.begin;
  manifest["classes"] = {{"positive", res.positive}, {"negative", res.negative}};
  manifest["outputs"] = json::array();
  for (auto& s : sinks) {
    for (const FileState& f : s->files()) {
      char hash[17];
      std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(f.xxh3));
      manifest["outputs"].push_back({{"name", f.name}, {"bytes", f.bytes}, {"xxh3_64", hash}});
    }
    s->finish();
  }
  if (plan.images) manifest["images"] = {{"folder", "images"}, {"count", res.end - res.begin}};
  write_text_atomic((out / "manifest.json").string(), manifest.dump(2) + "\n");
  fs::remove_all(state_dir, ec);
  return res;
}

}  // namespace portalsim
