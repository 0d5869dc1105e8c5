#include "sink/tensors.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>

#include "base/error.h"
#include "base/parallel.h"
#include "plan/knobs.h"
#include "plan/plan.h"
#include "sink/file_order_hash.h"
#include "sink/h5_file.h"
#include "sink/output_folder.h"

namespace portalsim {

namespace fs = std::filesystem;

std::string npy_array_header(const std::string& descr, const std::vector<uint64_t>& shape) {
  std::string dims;
  for (uint64_t d : shape) dims += std::to_string(d) + ", ";
  if (shape.size() > 1) dims.resize(dims.size() - 1);  // "(n, m)"; a 1-d shape keeps its comma: "(n,)"
  std::string dict = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Magic (6) + version (2) + length (2) + dict + padding + '\n', a multiple of 64.
  const size_t total = (10 + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - 10 - dict.size() - 1, ' ');
  dict.push_back('\n');
  std::string h("\x93NUMPY\x01\x00", 8);
  h.push_back(static_cast<char>(dict.size() & 0xff));
  h.push_back(static_cast<char>(dict.size() >> 8));
  return h + dict;
}

namespace {

// Rows [lo, hi) of `v`, whose rows are `row` elements each.
template <class T>
std::string_view rows_of(const std::vector<T>& v, size_t row, size_t lo, size_t hi) {
  return {reinterpret_cast<const char*>(v.data() + lo * row), (hi - lo) * row * sizeof(T)};
}

// One tensor and, unless data.h5 is written in place, its .npy file.
struct Tensor {
  TensorColumn col;
  std::unique_ptr<AppendFile> file;
};

// Rows of an int16 per-region tensor: `f` of each region's variant.
template <class F>
std::string_view per_region(const SceneBatch& b, size_t lo, size_t hi, char* dst, F f) {
  const size_t R = static_cast<size_t>(b.regions);
  for (size_t i = lo * R; i < hi * R; ++i) {
    const int16_t v = f(b.objects[i]);
    std::memcpy(dst + (i - lo * R) * sizeof(int16_t), &v, sizeof v);
  }
  return {dst, (hi - lo) * R * sizeof(int16_t)};
}

// Scenario i's region r: `of(object_transform(...))`, or `none` where the region is empty.
template <class T, class F>
std::string_view per_transform(const ModelSettings& model, const SceneBatch& b, size_t lo, size_t hi, char* dst, T none,
                               F of) {
  const int R = b.regions;
  for (size_t i = lo; i < hi; ++i)
    for (int r = 0; r < R; ++r) {
      const T v = b.objects[i * R + r] == kNoObject ? none : of(object_transform(model, b.first_index + i, r));
      std::memcpy(dst + ((i - lo) * R + r) * sizeof(T), &v, sizeof v);
    }
  return {dst, (hi - lo) * R * sizeof(T)};
}

// The columns being made: each one a dataset of `type` and `dims` per scenario, filled by
// `fill`; `view` where its rows are the outputs' own bytes.
struct ColumnList {
  const SinkContext& ctx;
  std::vector<TensorColumn> columns;
  void operator()(const std::string& name, TensorType type, std::vector<uint64_t> dims, Fill fill, bool view = false) {
    TensorColumn c;
    c.ds.name = name;
    c.ds.type = type;
    c.ds.dims = std::move(dims);
    if (name == "features") {
      c.ds.columns = ctx.layout.names();
      c.ds.columns.resize(static_cast<size_t>(ctx.layout.image_features()));
    }
    c.fill = std::move(fill);
    c.view = view;
    columns.push_back(std::move(c));
  }
};

// Each view's images (through its palette where it has one), masks, and the features.
void add_image_columns(ColumnList& add, const SinkContext& ctx, const TensorOptions& opt) {
  const Catalogue* cat = ctx.cat;
  if (opt.images)
    for (size_t k = 0; k < cat->sensors.size(); ++k) {
      const Sensor& s = cat->sensors[k];
      const uint64_t h = static_cast<uint64_t>(s.height), w = static_cast<uint64_t>(s.width);
      if (s.palette) {
        // Through the palette as 4-byte words, each store overlapping the next pixel's.
        std::array<uint32_t, 256> rgb{};
        for (size_t i = 0; i < rgb.size(); ++i) std::memcpy(&rgb[i], ctx.palette[i].data(), 3);
        add(s.name, TensorType::u8, {h, w, 3},
            [k, rgb](const SceneBatch&, const BatchOutput& o, size_t lo, size_t hi, char* d) {
              const ViewImages& v = o.views[k];
              const size_t per = v.pixels_per_image(), n = (hi - lo) * per;
              const uint8_t* p = v.pixels.data() + lo * per;
              if (n == 0) return std::string_view(d, 0);
              for (size_t i = 0; i + 1 < n; ++i) std::memcpy(d + i * 3, &rgb[p[i]], 4);
              std::memcpy(d + (n - 1) * 3, &rgb[p[n - 1]], 3);  // the last: no byte past the rows
              return std::string_view(d, n * 3);
            });
        add(
            s.name + "_index", TensorType::u8, {h, w},
            [k](const SceneBatch&, const BatchOutput& o, size_t lo, size_t hi, char*) {
              return rows_of(o.views[k].pixels, o.views[k].pixels_per_image(), lo, hi);
            },
            true);
      } else {
        add(
            s.name, TensorType::u8, {h, w},
            [k](const SceneBatch&, const BatchOutput& o, size_t lo, size_t hi, char*) {
              return rows_of(o.views[k].pixels, o.views[k].pixels_per_image(), lo, hi);
            },
            true);
      }
    }
  if (opt.annotations)
    for (size_t k = 0; k < cat->sensors.size(); ++k) {
      const Sensor& s = cat->sensors[k];
      add(
          "mask_" + s.name, TensorType::u8, {static_cast<uint64_t>(s.height), static_cast<uint64_t>(s.width)},
          [k, per = static_cast<size_t>(s.pixels())](const SceneBatch&, const BatchOutput& o, size_t lo, size_t hi,
                                                     char*) { return rows_of(o.annotations[k].masks, per, lo, hi); },
          true);
    }
  if (opt.features)
    add(
        "features", TensorType::f32, {static_cast<uint64_t>(ctx.layout.image_features())},
        [](const SceneBatch&, const BatchOutput& o, size_t lo, size_t hi, char*) {
          return rows_of(o.features, static_cast<size_t>(o.layout.image_features()), lo, hi);
        },
        true);
}

// Each region's object, drawing and label (by the threat rule, the object alone on the subject).
void add_region_columns(ColumnList& add, const SinkContext& ctx, const ThreatRule* rule) {
  const Catalogue* cat = ctx.cat;
  const uint64_t regions = static_cast<uint64_t>(cat->region_count());
  add("region_object", TensorType::i16, {regions},
      [cat](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
        return per_region(b, lo, hi, dst, [&](int16_t v) {
          return v == kNoObject ? int16_t(-1) : int16_t(cat->variant_list[v].object);
        });
      });
  add("region_orientation", TensorType::i16, {regions},
      [cat](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
        return per_region(b, lo, hi, dst, [&](int16_t v) {
          return v == kNoObject ? int16_t(-1) : int16_t(cat->variant_list[v].variant);
        });
      });
  add("region_label", TensorType::u8, {regions},
      [rule](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
        const int R = b.regions;
        const std::string_view rows(dst, (hi - lo) * R);
        std::memset(dst, 0, rows.size());
        if (!rule) return rows;
        for (size_t i = lo; i < hi; ++i)
          for (int r = 0; r < R; ++r) {
            const int16_t v = b.objects[i * R + r];
            if (v == kNoObject) continue;
            Scenario alone;
            alone.subject = b.subject[i];
            alone.objects[r] = v;
            dst[(i - lo) * R + r] = (*rule)(alone) ? 1 : 0;
          }
        return rows;
      });
}

// Each object's randomised draw (plan.h, object_transform), the numbers scenarios.csv
// records: float64 so they are the same doubles; identity where a region is empty.
void add_transform_columns(ColumnList& add, const SinkContext& ctx) {
  const ModelSettings model = ctx.model;
  const uint64_t regions = static_cast<uint64_t>(ctx.cat->region_count());
  add("region_rotation", TensorType::f64, {regions},
      [model](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
        return per_transform<double>(model, b, lo, hi, dst, 0.0, [](const ObjectTransform& x) { return x.rotation; });
      });
  add("region_scale", TensorType::f64, {regions},
      [model](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
        return per_transform<double>(model, b, lo, hi, dst, 1.0, [](const ObjectTransform& x) { return x.scale; });
      });
  add("region_flip", TensorType::u8, {regions},
      [model](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
        return per_transform<uint8_t>(model, b, lo, hi, dst, 0,
                                      [](const ObjectTransform& x) { return uint8_t(x.flip); });
      });
}

}  // namespace

std::vector<TensorColumn> tensor_columns(const SinkContext& ctx, const TensorOptions& opt) {
  ColumnList add{ctx, {}};
  const ModelSettings model = ctx.model;
  add_image_columns(add, ctx, opt);
  if (opt.scenario) {
    add(
        "metal", TensorType::u8, {static_cast<uint64_t>(ctx.cat->zones)},
        [](const SceneBatch&, const BatchOutput& o, size_t lo, size_t hi, char*) {
          return rows_of(o.metal, static_cast<size_t>(o.layout.zones), lo, hi);
        },
        true);
    add(
        "label", TensorType::u8, {},
        [](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char*) {
          return rows_of(b.label, 1, lo, hi);
        },
        true);
    add("subject", TensorType::u8, {}, [](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
      // 0: every scenario has its own body (scenarios.csv numbers and records it).
      for (size_t i = lo; i < hi; ++i) dst[i - lo] = static_cast<char>(b.own_bodies() ? 0 : b.subject[i] + 1);
      return std::string_view(dst, hi - lo);
    });
    add_region_columns(add, ctx, opt.rule);
    if (ctx.model.transforms()) add_transform_columns(add, ctx);
    // Each knob drawn per scenario (plan.h, drawn_knob_at): float64, the doubles
    // scenarios.csv records.
    for (const DrawnKnob& d : drawn_knobs())
      if (const unsigned e = d.element; d.number() && ctx.model.drawn[e].varies())
        add("param_" + d.key, TensorType::f64, {},
            [model, e](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
              for (size_t i = lo; i < hi; ++i) {
                const double v = drawn_knob_at(model, e, b.first_index + i);
                std::memcpy(dst + (i - lo) * sizeof v, &v, sizeof v);
              }
              return std::string_view(dst, (hi - lo) * sizeof(double));
            });
    // The raw grid drawn per scenario (plan.h, raw_grid_at), as scenarios.csv records it.
    if (ctx.model.raw_grid_drawn())
      for (size_t side = 0; side < kRawGridColumns.size(); ++side)
        add(kRawGridColumns[side], TensorType::i16, {},
            [model, side](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
              for (size_t i = lo; i < hi; ++i) {
                const int16_t v = static_cast<int16_t>(raw_grid_at(model, b.first_index + i)[side]);
                std::memcpy(dst + (i - lo) * sizeof v, &v, sizeof v);
              }
              return std::string_view(dst, (hi - lo) * sizeof(int16_t));
            });
    // The outfit drawn per scenario (plan.h, outfit_at), as scenarios.csv records it.
    if (ctx.model.clothing != Clothing::catalogue) {
      add("clothing_outfit", TensorType::i16, {},
          [model](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
            for (size_t i = lo; i < hi; ++i) {
              const int16_t v = static_cast<int16_t>(outfit_at(model, b.first_index + i));
              std::memcpy(dst + (i - lo) * sizeof v, &v, sizeof v);
            }
            return std::string_view(dst, (hi - lo) * sizeof(int16_t));
          });
      for (const bool transmission : {true, false})
        add(transmission ? "clothing_transmission" : "clothing_clo", TensorType::f64, {},
            [model, transmission](const SceneBatch& b, const BatchOutput&, size_t lo, size_t hi, char* dst) {
              for (size_t i = lo; i < hi; ++i) {
                const Outfit& o = outfit_of(model, b.first_index + i);
                const double v = transmission ? o.transmission() : o.clo();
                std::memcpy(dst + (i - lo) * sizeof v, &v, sizeof v);
              }
              return std::string_view(dst, (hi - lo) * sizeof(double));
            });
    }
  }
  return std::move(add.columns);
}

namespace {

// About the bytes of one piece of a tensor's rows (TensorSink::write), well inside a core's
// L2 cache, and how many pieces of data.h5 may be made before they are written.
constexpr size_t kPieceBytes = 256u << 10;
constexpr size_t kSlots = 8;

class TensorSink final : public Sink {
 public:
  TensorSink(const SinkContext& ctx, const TensorOptions& opt, const std::map<std::string, FileState>* resume)
      : ctx_(ctx), opt_(opt) {
    if (opt.h5 && opt.compress) {
      std::error_code ec;
      fs::create_directories(fs::path(ctx.dir) / kStateDir / "tensors", ec);
      if (ec) throw OutputError(ctx.dir + "/" + kStateDir + "/tensors: cannot create: " + ec.message());
    }
    for (TensorColumn& c : tensor_columns(ctx, opt)) tensors_.push_back(Tensor{std::move(c), nullptr});
    if (in_place())
      open_in_place(resume);
    else
      for (Tensor& t : tensors_) {
        const std::string file = file_name(t.col.ds.name);
        const FileState* state = nullptr;
        if (resume) {
          auto it = resume->find(file);
          if (it == resume->end()) throw OutputError(ctx.dir + "/.portalsim/checkpoint.json: no state for " + file);
          state = &it->second;
        }
        std::vector<uint64_t> shape{ctx.rows};
        shape.insert(shape.end(), t.col.ds.dims.begin(), t.col.ds.dims.end());
        const std::string header = npy_array_header(npy_descr(t.col.ds.type), shape);
        t.file = std::make_unique<AppendFile>(ctx.dir, file, state);
        if (!state) t.file->append(header);
      }
  }

  ~TensorSink() override {
    if (fd_ >= 0) ::close(fd_);
  }

  // Each tensor's rows go out in pieces of about kPieceBytes: made (the IR palette), hashed
  // and written while they are in the cache, where passes over whole batches would read
  // each batch from memory again for every step.
  void write(const SceneBatch& scenes, const BatchOutput& out) override {
    const size_t n = scenes.size();
    if (rows_ + n > ctx_.rows) throw std::logic_error("TensorSink: more rows than the run holds");
    struct Piece {
      Tensor* t;
      size_t lo, hi;          // the batch's rows
      size_t extent = 0;      // data.h5: the chunk's place in the file order (FileOrderHash)
      uint64_t at = 0;        // where in the chunk they go
      uint64_t file_at = 0;   // and in the file
      std::string_view rows;  // once made
    };
    std::vector<Piece> pieces;
    if (!in_place()) {
      for (Tensor& t : tensors_) {
        const size_t step = std::max<size_t>(1, kPieceBytes / std::max<size_t>(1, t.col.ds.row_bytes()));
        for (size_t lo = 0; lo < n; lo += step) pieces.push_back({&t, lo, std::min(n, lo + step), 0, 0, 0, {}});
      }
    } else {
      // Chunk by chunk, each dataset's part of it in turn: the order of the file.
      const uint64_t chunk_rows = place_.chunk_rows, end = rows_ + n;
      for (uint64_t c = rows_ / chunk_rows; c * chunk_rows < end; ++c) {
        const uint64_t from = std::max(rows_, c * chunk_rows), to = std::min(end, (c + 1) * chunk_rows);
        for (size_t k = 0; k < tensors_.size(); ++k) {
          const size_t row = std::max<size_t>(1, tensors_[k].col.ds.row_bytes());
          const size_t step = std::max<size_t>(1, kPieceBytes / row);
          for (uint64_t r = from; r < to; r += step)
            pieces.push_back({&tensors_[k],
                              static_cast<size_t>(r - rows_),
                              static_cast<size_t>(std::min<uint64_t>(to, r + step) - rows_),
                              static_cast<size_t>(c * tensors_.size() + k),
                              (r - c * chunk_rows) * row,
                              place_.at(k, r, row),
                              {}});
        }
      }
    }
    if (!in_place()) {
      // One file per tensor: the tensors are shared out among the threads, dealt in turn
      // (the camera views, most of the bytes, come first).
      const unsigned threads = std::min<unsigned>(ctx_.threads, static_cast<unsigned>(tensors_.size()));
      if (scratch_.size() < threads) scratch_.resize(threads);
      parallel_for(threads, threads, [&](size_t first, size_t) {
        for (size_t k = first; k < tensors_.size(); k += threads)
          for (const Piece& p : pieces)
            if (p.t == &tensors_[k]) p.t->file->append(p.t->col.rows(scenes, out, p.lo, p.hi, scratch_[first]));
      });
      return;
    }
    // data.h5: this thread makes each piece and feeds it to the file's hash while a second
    // thread writes the pieces before it (a write into one file holds its inode's lock on tmpfs and ext4, so
    // more writers would only wait for it). The piece made here lands in one of kSlots
    // buffers, which the writer must be done with. Each thread wakes the other only when it
    // sleeps, and this one sleeps until half the slots are free: a woken thread often runs
    // on the CPU of the one that woke it and takes it from the writer, which waking this one
    // after every piece did about a hundred times a batch.
    const auto make = [&](size_t i) {
      Piece& p = pieces[i];
      p.rows = p.t->col.rows(scenes, out, p.lo, p.hi, slots_[i % kSlots]);
      order_->feed(p.extent, p.at, p.rows);
    };
    const auto put = [&](const Piece& p) { write_at(fd_, p.rows.data(), p.rows.size(), p.file_at, partial_); };
    if (ctx_.threads < 2) {
      for (size_t i = 0; i < pieces.size(); ++i) {
        make(i);
        put(pieces[i]);
      }
    } else {
      std::mutex m;
      std::condition_variable made_cv, written_cv;
      size_t made = 0, written = 0;
      size_t maker_waits_for = 0;  // the writer wakes this thread once `written` reaches it; 0: awake
      bool writer_waits = false, failed = false;
      std::exception_ptr error;
      const auto fail = [&](std::exception_ptr e) {
        {
          std::lock_guard<std::mutex> lock(m);
          if (!error) error = e;
          failed = true;
        }
        made_cv.notify_all();
        written_cv.notify_all();
      };
      std::thread writer([&] {
        try {
          for (size_t i = 0; i < pieces.size(); ++i) {
            {
              std::unique_lock<std::mutex> lock(m);
              if (made <= i && !failed) {
                writer_waits = true;
                made_cv.wait(lock, [&] { return made > i || failed; });
                writer_waits = false;
              }
              if (failed) return;
            }
            put(pieces[i]);
            bool wake = false;
            {
              std::lock_guard<std::mutex> lock(m);
              written = i + 1;
              if (maker_waits_for && written >= maker_waits_for) {
                maker_waits_for = 0;
                wake = true;
              }
            }
            if (wake) written_cv.notify_all();
          }
        } catch (...) {
          fail(std::current_exception());
        }
      });
      try {
        for (size_t i = 0; i < pieces.size(); ++i) {
          {
            std::unique_lock<std::mutex> lock(m);
            if (written + kSlots <= i && !failed) {
              maker_waits_for = i + 1 - kSlots / 2;  // half the slots free
              written_cv.wait(lock, [&] { return maker_waits_for == 0 || failed; });
            }
            if (failed) break;
          }
          make(i);
          bool wake = false;
          {
            std::lock_guard<std::mutex> lock(m);
            made = i + 1;
            wake = writer_waits;
          }
          if (wake) made_cv.notify_all();
        }
      } catch (...) {
        fail(std::current_exception());
      }
      writer.join();
      if (error) std::rethrow_exception(error);
    }
    // On a disk, start the writeback of the rows just written (a hint, as in AppendFile), so
    // that it goes on while the run does and finish()'s fsync has little left to wait for.
    if (!pieces.empty()) {
      const uint64_t from = pieces.front().file_at, to = pieces.back().file_at + pieces.back().rows.size();
      if (to > from)
        ::sync_file_range(fd_, static_cast<off_t>(from), static_cast<off_t>(to - from), SYNC_FILE_RANGE_WRITE);
    }
    rows_ += n;
  }

  std::vector<FileState> files() const override {
    if (h5_state_) return {*h5_state_};
    // data.h5 in place: the file in order as far as it is written, and the pieces fed ahead of that.
    if (in_place()) return {FileState{kWrittenState, order_->position(), order_->digest()}, order_->held(kHeldState)};
    std::vector<FileState> f;
    for (const Tensor& t : tensors_) f.push_back(t.file->state());
    return f;
  }

  void finish() override {
    if (in_place()) {
      // The manifest's hash of data.h5 is the file-order hash, complete now.
      const uint64_t hash = order_->finish();
      struct stat st {};
      if (::fstat(fd_, &st) != 0 || static_cast<uint64_t>(st.st_size) != place_.file_size)
        throw OutputError(partial_ + ": not the size it was laid out at");
      if (::fsync(fd_) != 0) throw OutputError(partial_ + ": fsync failed: " + std::strerror(errno));
      const std::string final_path = (fs::path(ctx_.dir) / "data.h5").string();
      std::error_code ec;
      fs::rename(partial_, final_path, ec);
      if (ec) throw OutputError(final_path + ": cannot move into place: " + ec.message());
      h5_state_ = FileState{"data.h5", place_.file_size, hash};
      ::close(fd_);
      fd_ = -1;
      return;
    }
    for (Tensor& t : tensors_) t.file->finish();
    if (opt_.h5) build_h5();
  }

 private:
  SinkContext ctx_;
  TensorOptions opt_;
  std::vector<Tensor> tensors_;
  std::optional<FileState> h5_state_;
  std::string partial_;  // data.h5 in place: its name while the run goes
  int fd_ = -1;
  // data.h5 in place: where its chunks are, and the XXH3-64 of the file in order (the
  // manifest's, and the checkpoint's as far as it goes), fed as the pieces are made.
  H5InPlace place_;
  std::unique_ptr<FileOrderHash> order_;
  static constexpr const char* kWrittenState = "data.h5#written";
  static constexpr const char* kHeldState = "data.h5#held";
  uint64_t rows_ = 0;  // rows written so far
  // Where write() makes pieces, kept from batch to batch: data.h5's, and each thread's for .npy files.
  std::array<std::string, kSlots> slots_;
  std::vector<std::string> scratch_;

  // Uncompressed data.h5 is laid out at the start and its rows written in place; compressed,
  // it is built at the end from .npy files (HDF5 writes the chunks).
  bool in_place() const { return opt_.h5 && !opt_.compress; }

  H5Layout h5_layout() const {
    H5Layout layout;
    layout.rows = ctx_.rows;
    layout.compress = opt_.compress;
    layout.attributes = attributes();
    for (const Tensor& t : tensors_) layout.datasets.push_back(t.col.ds);
    return layout;
  }

  // Lays data.h5.partial out (a new run), or takes it back and checks that the file so far
  // is what the checkpoint recorded (a resumed run).
  void open_in_place(const std::map<std::string, FileState>* resume) {
    partial_ = (fs::path(ctx_.dir) / "data.h5.partial").string();
    const H5Layout layout = h5_layout();
    if (!resume) {
      place_ = create_h5_in_place(partial_, layout);
    } else {
      std::error_code ec;  // a run that died while renaming its finished file
      const fs::path final_path = fs::path(ctx_.dir) / "data.h5";
      if (!fs::exists(partial_, ec) && fs::exists(final_path, ec)) fs::rename(final_path, partial_, ec);
      place_ = h5_in_place_layout(partial_, layout, (fs::path(ctx_.dir) / kStateDir / "layout.h5").string());
    }
    fd_ = ::open(partial_.c_str(), O_RDWR | O_CLOEXEC);
    if (fd_ < 0) throw OutputError(partial_ + ": cannot open: " + std::strerror(errno));
    const uint64_t chunk_rows = place_.chunk_rows, chunks = (ctx_.rows + chunk_rows - 1) / chunk_rows;
    std::vector<FileExtent> extents;
    for (uint64_t c = 0; c < chunks; ++c)
      for (size_t k = 0; k < tensors_.size(); ++k) {
        const uint64_t row = tensors_[k].col.ds.row_bytes();
        extents.push_back({place_.address[k][c], chunk_rows * row,
                           (std::min(ctx_.rows, (c + 1) * chunk_rows) - c * chunk_rows) * row});
      }
    order_ = std::make_unique<FileOrderHash>(fd_, partial_, extents, place_.file_size);
    if (!resume) {
      order_->start();
      return;
    }
    const auto state = [&](const char* name) {
      auto it = resume->find(name);
      if (it == resume->end()) throw OutputError(ctx_.dir + "/.portalsim/checkpoint.json: no state for " + name);
      return it->second;
    };
    const FileState written = state(kWrittenState), held = state(kHeldState);
    std::string names;
    for (const Tensor& t : tensors_) names += (names.empty() ? "" : ", ") + t.col.ds.name;
    // The file in order up to where the checkpoint's hash reached; the rows written so far
    // end there, inside the first dataset's chunk (or at the end of the file).
    order_->skip_to(written.bytes, ctx_.threads);
    if (order_->digest() != written.xxh3)
      throw OutputError(partial_ + ": its bytes up to " + std::to_string(written.bytes) +
                        " (the rows written so far of datasets " + names +
                        ") differ from the checkpoint; the run cannot be resumed");
    if (order_->extent() == extents.size()) {
      rows_ = ctx_.rows;
    } else {
      const size_t e = order_->extent();
      const uint64_t at = order_->into_extent(), row = tensors_[0].col.ds.row_bytes();
      if (e % tensors_.size() != 0 || at % row != 0)
        throw OutputError(ctx_.dir + "/.portalsim/checkpoint.json: " + kWrittenState +
                          " does not end after a whole row of " + tensors_[0].col.ds.name);
      rows_ = e / tensors_.size() * chunk_rows + at / row;
    }
    if (rows_ != ctx_.done)
      throw OutputError(ctx_.dir + "/.portalsim/checkpoint.json: next says " + std::to_string(ctx_.done) +
                        " rows are written, " + kWrittenState + " " + std::to_string(rows_) +
                        "; the run cannot be resumed");
    // The rest of the rows so far (the other datasets' part of the chunk being written),
    // read back and fed ahead of the hash, as the run that wrote them did.
    if (rows_ % chunk_rows != 0 && rows_ < ctx_.rows) {
      const uint64_t c = rows_ / chunk_rows;
      std::string buf;
      for (size_t k = 1; k < tensors_.size(); ++k) {
        const uint64_t row = tensors_[k].col.ds.row_bytes();
        buf.resize((rows_ - c * chunk_rows) * row);
        read_at(fd_, buf.data(), buf.size(), place_.address[k][c], partial_, "for resume");
        order_->feed(c * tensors_.size() + k, 0, buf);
      }
    }
    const FileState now = order_->held(kHeldState);
    if (now.bytes != held.bytes || now.xxh3 != held.xxh3)
      throw OutputError(partial_ + ": the rows " + std::to_string(rows_ / chunk_rows * chunk_rows) + ".." +
                        std::to_string(rows_) + " of datasets " + names +
                        " differ from the checkpoint; the run cannot be resumed");
  }

  std::string file_name(const std::string& tensor) const {
    return opt_.h5 ? std::string(kStateDir) + "/tensors/" + tensor + ".npy" : tensor + ".npy";
  }
  // data.h5 from the finished tensor files (compressed).
  void build_h5() {
    std::vector<std::string> paths;
    for (const Tensor& t : tensors_) paths.push_back((fs::path(ctx_.dir) / file_name(t.col.ds.name)).string());
    write_h5(ctx_.dir, h5_layout(), paths);
    h5_state_ = hash_file(ctx_.dir, "data.h5", ctx_.threads);
  }

  std::vector<H5Attribute> attributes() const {
    const Catalogue& cat = *ctx_.cat;
    std::vector<H5Attribute> a;
    a.push_back({"portalsim", {opt_.identity.value("portalsim", std::string())}, true});
    a.push_back({"catalogue_hash", {cat.hash}, true});
    a.push_back({"spec", {opt_.identity.value("spec", nlohmann::json::object()).dump()}, true});
    a.push_back({"identity", {opt_.identity.dump()}, true});
    a.push_back({"class_names", {"negative", "positive"}, false});
    H5Attribute objects{"object_names", {}, false}, regions{"region_names", {}, false},
        drawings{"object_drawings", {}, false}, classes{"object_classes", {}, false},
        families{"object_families", {}, false};
    for (const Object& o : cat.objects) {
      objects.values.push_back(o.name);
      classes.values.push_back(o.object_class);
      families.values.push_back(o.family);
      std::string codes;  // region_orientation indexes these: "h,v", or "" for one drawing
      for (const Variant& v : o.variants) codes += (codes.empty() ? "" : ",") + v.code;
      drawings.values.push_back(codes);
    }
    for (const Region& r : cat.regions) regions.values.push_back(r.name);
    a.push_back(objects);
    a.push_back(regions);
    a.push_back(drawings);
    a.push_back(classes);
    a.push_back(families);
    a.push_back({"region_label_rule", {opt_.rule ? opt_.rule->text() : std::string()}, true});
    return a;
  }
};

}  // namespace

std::unique_ptr<Sink> make_tensor_sink(const SinkContext& ctx, const TensorOptions& opt,
                                       const std::map<std::string, FileState>* resume) {
  return std::make_unique<TensorSink>(ctx, opt, resume);
}

TensorOptions data_h5_options(const SinkRequest& r) {
  TensorOptions topt;
  topt.rule = r.rule;
  topt.annotations = r.annotations;
  topt.h5 = true;
  topt.compress = r.compress;
  topt.images = r.images;
  topt.features = r.features;
  topt.identity = r.identity;
  return topt;
}

// data.h5: every tensor of the run.
extern const SinkKind data_h5_kind{
    .name = "data.h5",
    .flag = "--format h5",
    .formats = {"h5"},
    .format_help = "h5: data.h5 with image tensors and labels",
    .wanted = [](const SinkRequest& r) { return r.has_format("h5"); },
    .open = [](const SinkRequest& r, const SinkContext& ctx, const SinkStart& start,
               Sinks& out) { out.push_back(make_tensor_sink(ctx, data_h5_options(r), start.saved)); },
    .writes = [](std::string_view f) { return f == "data.h5"; },
    .join = [](std::string_view) { return JoinAs::h5; },
    .refusal = "",
    .meaning =
        [](std::string_view, int, int) {
          return std::string("HDF5: every tensor, one row per scenario (the datasets are described in croissant.json)");
        }};

// <view>.npy and the scenario tensors as .npy files (--format npy with --what images).
extern const SinkKind npy_tensors_kind{
    .name = "<tensor>.npy",
    .flag = "--format npy --what images",
    .formats = {"npy"},
    .format_help = "npy with --what images: image tensors as .npy",
    .wanted = [](const SinkRequest& r) { return r.npy_image_tensors; },
    .open =
        [](const SinkRequest& r, const SinkContext& ctx, const SinkStart& start, Sinks& out) {
          TensorOptions topt = data_h5_options(r);
          topt.h5 = false;
          topt.images = true;
          out.push_back(make_tensor_sink(ctx, topt, start.saved));
        },
    .writes = [](std::string_view f) { return f.ends_with(".npy"); },
    .join = [](std::string_view) { return JoinAs::npy; },
    .refusal = "",
    .meaning = [](std::string_view, int, int) { return std::string(); }};  // the card's tensor words

}  // namespace portalsim
