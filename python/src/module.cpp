// portalsim._core: the simulator for Python. Generator.batch gives generate's data.h5 rows
// (schedule/scenario_source.h, sink/tensors.h: the same code makes them) as NumPy arrays
// that own the C++ buffers; simulate gives one scenario's outputs. The kernels run with the
// GIL released, and a Generator renders the next batch on its own thread meanwhile.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>

#include "base/error.h"
#include "base/parallel.h"
#include "base/recycler.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/python_requests.h"
#include "plan/knobs.h"
#include "schedule/body_pages.h"
#include "schedule/scenario_source.h"

namespace py = pybind11;
using namespace portalsim;

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// One batch: the backend's outputs and the rows made from them. NumPy arrays hold it
// through capsules; the last one freed hands it back to its generator's pool.
struct Rows {
  SceneBatch scenes{0};  // filled by ScenarioSource::fill, or with the catalogue's stride below
  BatchOutput out;
  std::vector<std::unique_ptr<char[]>> made;  // per column: the rows made here (not views)
  std::vector<size_t> made_bytes;
  std::vector<std::string_view> rows;  // per column

  // A new batch of `columns` columns, without rows; the buffers made before are kept.
  void start(size_t columns) {
    made.resize(columns);
    made_bytes.resize(columns, 0);
    rows.assign(columns, {});
  }
  // Column k's rows in a buffer of its own, of `bytes` (an earlier batch's where it is large
  // enough).
  char* own(size_t k, size_t bytes) {
    if (made_bytes[k] < bytes || !made[k]) {
      made[k].reset(new char[std::max<size_t>(1, bytes)]);
      made_bytes[k] = bytes;
    }
    rows[k] = std::string_view(made[k].get(), bytes);
    return made[k].get();
  }
};

// Finished batches whose buffers the next one reuses, so that a long stream touches no new
// pages: at most kKeptBatches are kept.
using Pool = Recycler<Rows>;
constexpr size_t kKeptBatches = 4;

py::dtype dtype_of(TensorType t) {
  switch (t) {
    case TensorType::u8:
      return py::dtype::of<uint8_t>();
    case TensorType::i16:
      return py::dtype::of<int16_t>();
    case TensorType::f32:
      return py::dtype::of<float>();
    case TensorType::f64:
      return py::dtype::of<double>();
  }
  throw std::logic_error("dtype_of: unknown tensor type");
}

// The columns' rows of `rows` as NumPy arrays (count, dims...), each owning a share of it.
py::dict to_arrays(const std::shared_ptr<Rows>& rows, const std::vector<TensorColumn>& columns, size_t n) {
  py::dict d;
  for (size_t k = 0; k < columns.size(); ++k) {
    const H5Dataset& ds = columns[k].ds;
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(n)};
    for (uint64_t v : ds.dims) shape.push_back(static_cast<py::ssize_t>(v));
    auto* keep = new std::shared_ptr<Rows>(rows);
    py::capsule owner(keep, [](void* p) { delete static_cast<std::shared_ptr<Rows>*>(p); });
    d[py::str(ds.name)] = py::array(dtype_of(ds.type), shape, rows->rows[k].data(), owner);
  }
  return d;
}

// Joins the rows of batches `parts` (in order) into `r`'s own buffers: a batch of
// per-scenario bodies that crosses a page is made a page's part at a time.
void join_rows(Rows& r, const std::vector<Rows>& parts, const std::vector<TensorColumn>& columns, size_t n) {
  r.start(columns.size());
  for (size_t k = 0; k < columns.size(); ++k) {
    const size_t bytes = n * columns[k].ds.row_bytes();
    char* dst = r.own(k, bytes);
    size_t at = 0;
    for (const Rows& p : parts) {
      if (at + p.rows[k].size() > bytes) throw std::logic_error("join_rows: the parts hold more rows than the batch");
      std::memcpy(dst + at, p.rows[k].data(), p.rows[k].size());
      at += p.rows[k].size();
    }
    if (at != bytes) throw std::logic_error("join_rows: the parts hold fewer rows than the batch");
  }
}

// Makes each column's rows of a computed batch: the views point into the batch, the rest
// (the IR palette, labels by region, ...) are made in pieces on `threads` threads.
void make_rows(Rows& r, const std::vector<TensorColumn>& columns, unsigned threads) {
  const size_t n = r.scenes.size();
  r.start(columns.size());
  struct Piece {
    size_t column, lo, hi;
  };
  std::vector<Piece> pieces;
  for (size_t k = 0; k < columns.size(); ++k) {
    if (columns[k].view) {
      r.rows[k] = columns[k].fill(r.scenes, r.out, 0, n, nullptr);
      continue;
    }
    const size_t row = std::max<size_t>(1, columns[k].ds.row_bytes());
    r.own(k, n * row);
    const size_t step = std::max<size_t>(1, (256u << 10) / row);  // pieces of about 256 KiB
    for (size_t lo = 0; lo < n; lo += step) pieces.push_back({k, lo, std::min(n, lo + step)});
  }
  const unsigned t = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(pieces.size())));
  parallel_for(t, t, [&](size_t first, size_t) {
    for (size_t i = first; i < pieces.size(); i += t) {
      const Piece& p = pieces[i];
      const size_t row = columns[p.column].ds.row_bytes();
      // Straight into the array's memory: no scratch, no copy.
      columns[p.column].fill(r.scenes, r.out, p.lo, p.hi, r.made[p.column].get() + p.lo * row);
    }
  });
}

// The process that made an OpenCL context here: PoCL hangs in a process forked from one
// that had made one, so a forked child that would make its own fails with a message instead.
pid_t g_opencl_pid = 0;

void open_backend_here(cli::Session& s, const cli::CommonOptions& common) {
  if (common.backend == "opencl") {
    if (g_opencl_pid != 0 && g_opencl_pid != ::getpid())
      throw EnvironmentError("portalsim: this process was forked from one that had made an OpenCL context (process " +
                             std::to_string(g_opencl_pid) +
                             "), and PoCL hangs in such a child: render only in the workers, or start them with "
                             "DataLoader(multiprocessing_context=\"spawn\")");
    g_opencl_pid = ::getpid();
  }
  cli::open_backend(s, common);
}

// generate's run of a spec, a batch at a time, in memory.
class Engine {
 public:
  // `datasets`: the data.h5 datasets to make (all where none are named); only what they
  // need is computed.
  Engine(const std::vector<std::string>& args, const std::optional<std::vector<std::string>>& datasets)
      : req_(cli::parse_generate(args)) {
    cli::open_catalogue(session_, req_.common, &req_.spec, req_.spec.settings().model.has_folds());
    cli::check_generate(req_.spec, session_.catalogue);
    source_.emplace(req_.spec, session_.catalogue);
    plan_ = run_plan(req_.spec, session_.catalogue);
    threads_ = req_.threads ? req_.threads : default_threads();
    ctx_ = plan_sink_context(plan_, session_.catalogue, session_.assets, threads_, req_.spec.image_format);
    const TensorOptions topt = data_h5_options(sink_request(req_.spec, plan_, source_->rule()));
    columns_ = tensor_columns(ctx_, topt);
    if (datasets) {
      TensorOptions every = topt;  // every dataset a data.h5 of this catalogue can hold
      every.images = every.features = every.annotations = true;
      select(*datasets, tensor_columns(ctx_, every));
    }
  }
  const std::vector<TensorColumn>& columns() const { return columns_; }
  const ScenarioSource& source() const { return *source_; }

  // Keeps the columns named in `names` (data.h5's order stays), and narrows the plan to what
  // they read: a view is rendered only for its own datasets (or for features), masks only
  // for mask_*, features and metal zones only when named. Each kept column's bytes are the
  // same as with every column made: no output depends on another being computed. `every`:
  // the columns of every dataset there is (images, features and annotations on), so that a
  // name that is no dataset at all is told before one these keywords do not make.
  void select(const std::vector<std::string>& names, const std::vector<TensorColumn>& every) {
    const auto named = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) != names.end(); };
    const auto list = [](const std::vector<TensorColumn>& cs) {
      std::string all;
      for (const TensorColumn& c : cs) all += (all.empty() ? "" : ", ") + c.ds.name;
      return all;
    };
    const auto in = [](const std::vector<TensorColumn>& cs, const std::string& n) {
      return std::any_of(cs.begin(), cs.end(), [&](const TensorColumn& c) { return c.ds.name == n; });
    };
    for (const std::string& n : names)
      if (!in(every, n))
        throw InputError("datasets: \"" + n + "\" is not a dataset (the datasets are " + list(every) + ")");
    for (const std::string& n : names) {
      if (std::count(names.begin(), names.end(), n) > 1) throw InputError("datasets: \"" + n + "\" is named twice");
      if (!in(columns_, n))
        throw InputError("datasets: \"" + n + "\" is not a dataset of these keywords (they make " + list(columns_) +
                         "; what=\"images\" or \"both\" makes the views, annotations=True the masks)");
    }
    if (names.empty()) throw InputError("datasets: name at least one dataset");
    std::erase_if(columns_, [&](const TensorColumn& c) { return !named(c.ds.name); });
    uint32_t images = 0;
    bool masks = false;
    for (size_t k = 0; k < session_.catalogue.sensors.size(); ++k) {
      const std::string& v = session_.catalogue.sensors[k].name;
      if (named(v) || named(v + "_index")) images |= 1u << k;
      masks = masks || named("mask_" + v);
    }
    plan_.images &= images;
    plan_.annotations = plan_.annotations && masks;
    plan_.features = plan_.features && named("features");
    plan_.metal = plan_.metal && named("metal");
  }
  const cli::GenerateRequest& request() const { return req_; }

  // Scenarios [start, start + count): their rows. The OpenCL context is made on the first
  // call, in the process that renders (never before a fork).
  std::unique_ptr<Rows> compute(uint64_t start, size_t count, Pool& pool) {
    if (source_->listed() && (start > source_->total() || count > source_->total() - start))
      throw InputError("batch: scenarios " + std::to_string(start) + ".." + std::to_string(start + count) +
                       " are past the end of the scenario list (" + std::to_string(source_->total()) + ")");
    if (!session_.backend) {
      open_backend_here(session_, req_.common);
      if (req_.spec.per_scenario_bodies())
        pages_.emplace(session_.catalogue, session_.assets, *session_.backend, req_.spec.bodies_seed());
    }
    std::unique_ptr<Rows> r = pool.take();
    if (!pages_ || body_page(start) == body_page(start + count - 1)) {
      make(start, count, *r);
      return r;
    }
    // Per-scenario bodies: a page's scenarios run on that page's backend (schedule/body_pages.h).
    std::vector<Rows> parts;  // never moved: a part's rows may point into its own output
    parts.reserve(static_cast<size_t>(body_page(start + count - 1) - body_page(start) + 1));
    for (uint64_t lo = start; lo < start + count;) {
      const uint64_t hi = std::min<uint64_t>(start + count, (body_page(lo) + 1) * kBodyPage);
      make(lo, static_cast<size_t>(hi - lo), parts.emplace_back());
      lo = hi;
    }
    join_rows(*r, parts, columns_, count);
    return r;
  }

  // Where the time of all batches so far went (for bench/python_bench.py).
  struct Times {
    uint64_t scenarios = 0;
    double scenes = 0, kernels = 0, rows = 0;  // making the scenarios, the backend, the rows
  };
  Times times() {
    std::lock_guard<std::mutex> lock(times_m_);
    return times_;
  }

 private:
  cli::GenerateRequest req_;
  cli::Session session_;
  std::optional<BodyPages> pages_;  // per-scenario bodies: each page's catalogue and backend
  std::optional<ScenarioSource> source_;
  Plan plan_;
  unsigned threads_ = 1;
  SinkContext ctx_;
  std::vector<TensorColumn> columns_;
  std::mutex times_m_;
  Times times_;

  // Scenarios [start, start + count), all in one page where bodies are per scenario: their rows.
  void make(uint64_t start, size_t count, Rows& r) {
    const auto t0 = Clock::now();
    source_->fill(start, count, threads_, r.scenes);
    Backend& backend = pages_ ? pages_->backend_for(body_page(start), r.scenes) : *session_.backend;
    const auto t1 = Clock::now();
    backend.run(r.scenes, plan_, r.out);
    const auto t2 = Clock::now();
    make_rows(r, columns_, threads_);
    const auto t3 = Clock::now();
    std::lock_guard<std::mutex> lock(times_m_);
    times_.scenarios += count;
    times_.scenes += seconds(t0, t1);
    times_.kernels += seconds(t1, t2);
    times_.rows += seconds(t2, t3);
  }
};

// An Engine and the thread that renders the batch after the one asked for, while Python
// reads that one.
class StreamGenerator {
 public:
  StreamGenerator(const std::vector<std::string>& args, bool prefetch,
                  const std::optional<std::vector<std::string>>& datasets)
      : engine_(args, datasets), pool_(std::make_shared<Pool>(kKeptBatches)), prefetch_(prefetch) {
    if (prefetch_) worker_ = std::thread([this] { work(); });
  }
  ~StreamGenerator() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    cv_.notify_all();
    if (worker_.joinable()) worker_.join();
  }

  // `next`: the start of the batch to render ahead (of `count` scenarios), or none.
  py::dict batch(uint64_t start, size_t count, std::optional<uint64_t> next) {
    if (count < 1 || count > (1u << 24))
      throw InputError("batch: count: " + std::to_string(count) + " is not between 1 and 2^24");
    std::unique_ptr<Rows> r;
    {
      py::gil_scoped_release nogil;
      std::lock_guard<std::mutex> one_call(call_m_);  // one batch() at a time uses the backend
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait(lock, [&] { return !busy_; });
      if (ahead_ && ahead_start_ == start && ahead_count_ == count) {
        std::exception_ptr e = std::exchange(ahead_error_, nullptr);
        r = std::move(ahead_);
        ahead_.reset();
        if (e) std::rethrow_exception(e);
      } else {
        ahead_.reset();
        ahead_error_ = nullptr;
        lock.unlock();
        r = engine_.compute(start, count, *pool_);
        lock.lock();
      }
      const ScenarioSource& src = engine_.source();
      if (prefetch_ && next && (!src.listed() || (*next <= src.total() && count <= src.total() - *next))) {
        next_start_ = *next;
        next_count_ = count;
        busy_ = true;
        cv_.notify_all();
      }
    }
    std::weak_ptr<Pool> pool = pool_;
    std::shared_ptr<Rows> shared(r.release(), [pool](Rows* p) {
      if (auto q = pool.lock())
        q->give(std::unique_ptr<Rows>(p));
      else
        delete p;
    });
    return to_arrays(shared, engine_.columns(), count);
  }

  py::list datasets() const {
    py::list l;
    for (const TensorColumn& c : engine_.columns()) l.append(c.ds.name);
    return l;
  }
  uint64_t count() const { return engine_.source().total(); }
  uint64_t seed() const { return engine_.request().spec.seed; }
  py::dict times() {
    const Engine::Times t = engine_.times();
    py::dict d;
    d["scenarios"] = t.scenarios;
    d["scenes"] = t.scenes;
    d["kernels"] = t.kernels;
    d["rows"] = t.rows;
    return d;
  }

 private:
  Engine engine_;
  std::shared_ptr<Pool> pool_;
  bool prefetch_;
  std::thread worker_;
  std::mutex call_m_, m_;
  std::condition_variable cv_;
  bool busy_ = false, stop_ = false;
  uint64_t next_start_ = 0, ahead_start_ = 0;
  size_t next_count_ = 0, ahead_count_ = 0;
  std::unique_ptr<Rows> ahead_;
  std::exception_ptr ahead_error_;

  void work() {
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      cv_.wait(lock, [&] { return busy_ || stop_; });
      if (stop_) return;
      const uint64_t start = next_start_;
      const size_t count = next_count_;
      lock.unlock();
      std::unique_ptr<Rows> r;
      std::exception_ptr e;
      try {
        r = engine_.compute(start, count, *pool_);
      } catch (...) {
        e = std::current_exception();
      }
      lock.lock();
      ahead_ = std::move(r);
      ahead_error_ = e;
      ahead_start_ = start;
      ahead_count_ = count;
      if (e) ahead_ = std::make_unique<Rows>();  // a marker: the error is for this batch
      busy_ = false;
      cv_.notify_all();
    }
  }
};

// One scenario as simulate makes it: every view (gray, and IR as RGB and index), the
// features, the metal zones and the labels, each without the scenario axis.
py::dict simulate(const std::vector<std::string>& args) {
  std::shared_ptr<Rows> rows;
  std::vector<TensorColumn> columns;
  {
    py::gil_scoped_release nogil;
    cli::Session s;
    const cli::SimulateRequest flags = cli::parse_simulate(args, nullptr);
    cli::open_catalogue(s, flags.common, &flags.bodies);
    const cli::SimulateRequest req = cli::parse_simulate(args, &s.catalogue);
    open_backend_here(s, req.common);
    Plan plan = req.plan;
    plan.images = kAllViews;
    plan.features = plan.metal = true;
    auto r = std::make_shared<Rows>();
    r->scenes.first_index = 0;
    r->scenes.regions = s.catalogue.region_count();
    r->scenes.subject = {static_cast<uint8_t>(req.scene.subject)};
    r->scenes.objects.assign(req.scene.objects.begin(), req.scene.objects.begin() + r->scenes.regions);
    r->scenes.label = {static_cast<uint8_t>(req.scene.label)};
    s.backend->run(r->scenes, plan, r->out);
    const SinkContext ctx = plan_sink_context(plan, s.catalogue, s.assets, 1, "png");
    TensorOptions topt;
    topt.images = topt.features = true;
    columns = tensor_columns(ctx, topt);
    make_rows(*r, columns, 1);
    rows = r;
  }
  py::dict d = to_arrays(rows, columns, 1), one;
  for (auto item : d) one[item.first] = item.second.cast<py::array>()[py::int_(0)];
  return one;
}

// The names of generate's and simulate's flags (without "--") and which take no value.
py::dict flags(const std::string& command) {
  CLI::App app;
  if (command == "generate")
    cli::add_generate(app);
  else
    cli::add_simulate(app);
  py::dict d;
  const CLI::App* sub = app.get_subcommand(command);
  for (const CLI::Option* o : sub->get_options()) {
    if (o == sub->get_help_ptr() || o == sub->get_help_all_ptr()) continue;  // --help is no keyword
    const std::string name = o->get_name();
    if (name.rfind("--", 0) != 0) continue;
    d[py::str(name.substr(2))] = o->get_expected_min() == 0;
  }
  return d;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "portalsim's C++ core (use the portalsim package)";
  m.attr("version") = PORTALSIM_VERSION;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const OutputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const EnvironmentError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  py::class_<StreamGenerator>(m, "Generator")
      .def(py::init<const std::vector<std::string>&, bool, const std::optional<std::vector<std::string>>&>(),
           py::arg("args"), py::arg("prefetch") = true, py::arg("datasets") = py::none())
      .def("batch", &StreamGenerator::batch, py::arg("start"), py::arg("count"), py::arg("next"))
      .def_property_readonly("datasets", &StreamGenerator::datasets)
      .def_property_readonly("count", &StreamGenerator::count)
      .def_property_readonly("seed", &StreamGenerator::seed)
      .def("times", &StreamGenerator::times);
  m.def("simulate", &simulate, py::arg("args"));
  m.def("flags", &flags, py::arg("command"));
}
