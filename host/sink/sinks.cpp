#include "sink/sinks.h"

#include <array>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "assets/image_io.h"
#include "base/error.h"
#include "base/parallel.h"
#include "plan/knobs.h"
#include "scene/bodies.h"
#include "sink/feature_rows.h"
#include "sink/scenario_folder.h"
#include "sink/sink_kinds.h"
#include "sink/staging.h"
#include "sink/tensors.h"

namespace portalsim {

namespace fs = std::filesystem;

std::string image_folder_name(uint64_t index) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%08llu", static_cast<unsigned long long>(index));
  return buf;
}

std::string arff_header(const FeatureLayout& layout) {
  std::string h = "% portalsim features: MMW block means, region means, metal zones (thesis 5.6)\n";
  h += "@relation portalsim\n\n";
  for (const std::string& n : layout.names()) h += "@attribute " + n + " numeric\n";
  h += "@attribute class {positive,negative}\n\n@data\n";
  return h;
}

std::string npy_header(uint64_t rows, size_t columns) { return npy_array_header("<f4", {rows, columns}); }

namespace {

// Rows formatted in parallel chunks, appended in order.
class TextTableSink final : public Sink {
 public:
  TextTableSink(const std::string& name, const std::string& header, const SinkContext& ctx, const FileState* resume)
      : ctx_(ctx), file_(ctx.dir, name, resume) {
    if (!resume) file_.append(header);
  }
  void write(const SceneBatch& scenes, const BatchOutput& out) override {
    const size_t n = scenes.size();
    const unsigned parts = std::min<unsigned>(ctx_.threads, static_cast<unsigned>(std::max<size_t>(1, n / 256)));
    std::vector<std::string> chunks(std::max(1u, parts));
    parallel_for(chunks.size(), parts, [&](size_t b, size_t e) {
      for (size_t c = b; c < e; ++c) {
        std::string& s = chunks[c];
        s.reserve((n / chunks.size() + 1) * 8 * static_cast<size_t>(out.layout.row_features()));
        for (size_t i = n * c / chunks.size(); i < n * (c + 1) / chunks.size(); ++i)
          append_feature_row(s, out, i, scenes.label[i] == 1);
      }
    });
    for (const std::string& s : chunks) file_.append(s);
  }
  std::vector<FileState> files() const override { return {file_.state()}; }
  void finish() override { file_.finish(); }

 private:
  SinkContext ctx_;
  AppendFile file_;
};

class NpySink final : public Sink {
 public:
  NpySink(const SinkContext& ctx, const FileState* resume, const std::string& name)
      : ctx_(ctx), columns_(static_cast<size_t>(ctx.layout.row_features()) + 1), file_(ctx.dir, name, resume) {
    if (!resume) {
      file_.append(npy_header(ctx.rows, columns_));
      std::string names;
      for (const std::string& n : ctx.layout.names()) names += n + "\n";
      write_text_atomic((fs::path(ctx.dir) / (fs::path(name).stem().string() + ".columns.txt")).string(),
                        names + "class\n");
    }
  }
  // Each row is assembled where the file is written from (AppendFile::room), but for a row
  // that would straddle its buffers.
  void write(const SceneBatch& scenes, const BatchOutput& out) override {
    const size_t n = scenes.size(), F = static_cast<size_t>(out.layout.image_features());
    const size_t row_bytes = columns_ * sizeof(float);
    buf_.resize(columns_);
    for (size_t i = 0; i < n; ++i) {
      const std::span<char> room = file_.room();
      char* row = room.size() >= row_bytes ? room.data() : reinterpret_cast<char*>(buf_.data());
      std::memcpy(row, out.features_of(i), F * sizeof(float));
      const int Z = out.layout.zones;
      std::array<float, kMaxZones + 1> tail;  // the metal zones, then the class
      for (int z = 0; z < Z; ++z) tail[z] = out.metal_of(i)[z];
      tail[Z] = scenes.label[i] == 1 ? 1.0f : 0.0f;
      std::memcpy(row + F * sizeof(float), tail.data(), (Z + 1) * sizeof(float));
      if (row == room.data())
        file_.commit(row_bytes);
      else
        file_.append(row, row_bytes);
    }
  }
  std::vector<FileState> files() const override { return {file_.state()}; }
  void finish() override { file_.finish(); }

 private:
  SinkContext ctx_;
  size_t columns_;
  AppendFile file_;
  std::vector<float> buf_;
};

class ScenarioListSink final : public Sink {
 public:
  ScenarioListSink(const SinkContext& ctx, const FileState* resume)
      : ctx_(ctx), file_(ctx.dir, "scenarios.csv", resume) {
    if (!resume) {
      std::string h = "index,subject";
      const int R = ctx.cat->region_count();
      for (int r = 1; r <= R; ++r) h += ",region" + std::to_string(r);
      if (ctx.model.transforms())
        for (const char* what : {",rotation", ",scale", ",flip"})
          for (int r = 1; r <= R; ++r) h += what + std::to_string(r);
      for (const DrawnKnob& d : drawn_knobs())
        if (d.number() && ctx.model.drawn[d.element].varies()) h += "," + d.key;
      if (ctx.model.raw_grid_drawn())
        for (const char* c : kRawGridColumns) h += std::string(",") + c;
      if (drawn_bodies(*ctx.cat))
        for (const char* c : kBodyColumns) h += std::string(",") + c;
      if (ctx.model.clothing != Clothing::catalogue)
        for (const char* c : kClothingColumns) h += std::string(",") + c;
      file_.append(h + ",label\n");
    }
    for (size_t v = 0; v < ctx.cat->variant_list.size(); ++v)
      names_.push_back(ctx.cat->variant_name(static_cast<int>(v)));
  }
  void write(const SceneBatch& scenes, const BatchOutput&) override {
    std::string s;
    const int R = scenes.regions;
    s.reserve(scenes.size() * 96);
    for (size_t i = 0; i < scenes.size(); ++i) {
      s += std::to_string(scenes.first_index + i);
      s += ',';
      // 0: the scenario's own body (per-scenario bodies; its columns below record it).
      s += std::to_string(scenes.own_bodies() ? 0u : scenes.subject[i] + 1u);
      for (int r = 0; r < R; ++r) {
        s += ',';
        const int16_t v = scenes.objects[i * R + r];
        s += v == kNoObject ? std::string("none") : names_[v];
      }
      if (ctx_.model.transforms()) {
        // Each object's draw (plan.h, object_transform), exactly: the shortest text that
        // reads back as the same double. Empty where a region has no object.
        std::array<ObjectTransform, kMaxRegions> t;
        for (int r = 0; r < R; ++r)
          if (scenes.objects[i * R + r] != kNoObject) t[r] = object_transform(ctx_.model, scenes.first_index + i, r);
        for (int what = 0; what < 3; ++what)
          for (int r = 0; r < R; ++r) {
            s += ',';
            if (scenes.objects[i * R + r] == kNoObject) continue;
            if (what == 2) {
              s += t[r].flip ? '1' : '0';
              continue;
            }
            char buf[32];
            const auto res = std::to_chars(buf, buf + sizeof buf, what == 0 ? t[r].rotation : t[r].scale);
            s.append(buf, res.ptr);
          }
      }
      // Each knob drawn per scenario (plan.h, drawn_knob_at): the shortest text that reads
      // back as the same double.
      for (const DrawnKnob& d : drawn_knobs())
        if (d.number() && ctx_.model.drawn[d.element].varies()) {
          char buf[32];
          const auto res =
              std::to_chars(buf, buf + sizeof buf, drawn_knob_at(ctx_.model, d.element, scenes.first_index + i));
          s += ',';
          s.append(buf, res.ptr);
        }
      if (ctx_.model.raw_grid_drawn()) {
        const std::array<int, 2> g = raw_grid_at(ctx_.model, scenes.first_index + i);
        s += ',' + std::to_string(g[0]) + ',' + std::to_string(g[1]);
      }
      const std::string& body = scenes.own_bodies() ? scenes.bodies[i] : ctx_.cat->subjects[scenes.subject[i]].drawn;
      if (!body.empty()) {
        s += ',';
        s += body;
      }
      if (ctx_.model.clothing != Clothing::catalogue) {
        // The outfit (plan.h, outfit_at), then its transmission and clo, shortest exact text.
        const Outfit& o = outfit_of(ctx_.model, scenes.first_index + i);
        s += ',';
        s += o.name();
        for (const double v : {o.transmission(), o.clo()}) {
          char buf[32];
          const auto res = std::to_chars(buf, buf + sizeof buf, v);
          s += ',';
          s.append(buf, res.ptr);
        }
      }
      s += scenes.label[i] == 1 ? ",yes\n" : ",no\n";
    }
    file_.append(s);
  }
  std::vector<FileState> files() const override { return {file_.state()}; }
  void finish() override { file_.finish(); }

 private:
  SinkContext ctx_;
  AppendFile file_;
  std::vector<std::string> names_;
};

class ImageSink final : public Sink {
 public:
  ImageSink(const SinkContext& ctx, bool resume, uint64_t resume_from) : ctx_(ctx) {
    root_ = (fs::path(ctx.dir) / "images").string();
    std::error_code ec;
    fs::create_directories(root_, ec);
    if (ec) throw OutputError(root_ + ": cannot create: " + ec.message());
    if (resume) {
      // Drop what the interrupted run wrote past its checkpoint, and its staging folders.
      for (const auto& entry : fs::directory_iterator(root_)) {
        const std::string name = entry.path().filename().string();
        const bool staging = name.find(".tmp") != std::string::npos;
        bool past = false;
        if (!staging && !name.empty() && name.find_first_not_of("0123456789") == std::string::npos)
          past = std::stoull(name) >= resume_from;
        if (staging || past) fs::remove_all(entry.path(), ec);
      }
    }
  }
  void write(const SceneBatch& scenes, const BatchOutput& out) override {
    // Each scenario's folder is written under <name>.tmp and renamed whole. Encoding is
    // nearly all of the work, on every thread (ctx.threads), beside the kernels computing
    // the next batch (pipeline.cpp).
    const FolderOptions opt{ctx_.image_format, ctx_.png_level};
    parallel_for(scenes.size(), ctx_.threads, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const std::string name = image_folder_name(scenes.first_index + i);
        const std::string tmp = root_ + "/" + name + ".tmp", final_path = root_ + "/" + name;
        std::error_code ec;
        // Left over only by a failed batch of this run (resume removed older ones).
        if (!fs::create_directory(tmp, ec) && !ec) {
          fs::remove_all(tmp, ec);
          fs::create_directory(tmp, ec);
        }
        if (ec) throw OutputError(tmp + ": cannot create: " + ec.message());
        write_scenario_folder([&](const std::string& f) { return tmp + "/" + f; }, out, i, scenes.label[i] == 1,
                              ctx_.palette, opt);
        fs::rename(tmp, final_path, ec);
        if (ec) {  // a folder of that name is there already (a retried batch): replace it
          fs::remove_all(final_path, ec);
          fs::rename(tmp, final_path, ec);
        }
        if (ec) throw OutputError(final_path + ": cannot move into place: " + ec.message());
      }
    });
  }
  std::vector<FileState> files() const override { return {}; }
  void finish() override {}

 private:
  SinkContext ctx_;
  std::string root_;
};

}  // namespace

std::unique_ptr<Sink> make_table_sink(const std::string& format, const SinkContext& ctx, const FileState* resume,
                                      const std::string& name) {
  const std::string file = name.empty() ? "features." + format : name;
  if (format == "csv") return std::make_unique<TextTableSink>(file, feature_csv_header(ctx.layout), ctx, resume);
  if (format == "arff") return std::make_unique<TextTableSink>(file, arff_header(ctx.layout), ctx, resume);
  if (format == "npy") return std::make_unique<NpySink>(ctx, resume, file);
  throw InputError("--format: unknown format \"" + format + "\" (arff, csv, npy)");
}

std::unique_ptr<Sink> make_scenario_list_sink(const SinkContext& ctx, const FileState* resume) {
  return std::make_unique<ScenarioListSink>(ctx, resume);
}

std::unique_ptr<Sink> make_image_sink(const SinkContext& ctx, bool resume, uint64_t resume_from) {
  return std::make_unique<ImageSink>(ctx, resume, resume_from);
}

// scenarios.csv: every run writes it.
extern const SinkKind scenario_list_kind{
    .name = "scenarios.csv",
    .flag = "generate",
    .formats = {},
    .format_help = "",
    .wanted = [](const SinkRequest&) { return true; },
    .open = [](const SinkRequest&, const SinkContext& ctx, const SinkStart& start,
               Sinks& out) { out.push_back(make_scenario_list_sink(ctx, start.state(ctx.dir, "scenarios.csv"))); },
    .writes = [](std::string_view f) { return f == "scenarios.csv"; },
    .join = [](std::string_view) { return JoinAs::text; },
    .refusal = "",
    .meaning =
        [](std::string_view, int regions, int) {
          return "the scenario list: subject, the object in each of the " + std::to_string(regions) +
                 " regions, the label (and each object's random transform); generate --scenarios makes the data set "
                 "again from it";
        }};

namespace {
bool table_format(std::string_view f) { return f == "arff" || f == "csv" || f == "npy"; }
}  // namespace

// The feature tables, one per --format value, in the order given.
extern const SinkKind feature_tables_kind{
    .name = "features.<format>",
    .flag = "--format",
    .formats = {"arff", "csv", "npy"},
    .format_help = "arff,csv,npy feature tables",
    .wanted =
        [](const SinkRequest& r) {
          return r.features &&
                 std::any_of(r.formats.begin(), r.formats.end(), [](const std::string& f) { return table_format(f); });
        },
    .open =
        [](const SinkRequest& r, const SinkContext& ctx, const SinkStart& start, Sinks& out) {
          for (const std::string& f : r.formats)
            if (table_format(f)) out.push_back(make_table_sink(f, ctx, start.state(ctx.dir, "features." + f)));
        },
    .writes =
        [](std::string_view f) {
          return f == "features.arff" || f == "features.csv" || f == "features.npy" || f == "features.columns.txt";
        },
    .join = [](std::string_view f) { return f.ends_with(".npy") ? JoinAs::npy : JoinAs::text; },
    .refusal = "",
    .meaning = [](std::string_view f, int, int zones) -> std::string {
      const std::string rows = "the image features, the " + std::to_string(zones) + " metal zones and the class";
      if (f == "features.arff") return "WEKA ARFF: one row per scenario: " + rows;
      if (f == "features.csv") return "the same rows as CSV with a header: " + rows;
      if (f == "features.npy")
        return "float32 matrix, one row per scenario: " + rows + " (1/0) last; column names in features.columns.txt";
      return "the names of features.npy's columns, one a line";
    }};

// images/<index>/ folders, where images are not tensors. Not among the manifest's outputs:
// its `images` entry says they are there, and merge links them (join.cpp).
extern const SinkKind image_folders_kind{
    .name = "images/",
    .flag = "--what images",
    .formats = {},
    .format_help = "",
    .wanted = [](const SinkRequest& r) { return r.images && !r.image_tensors; },
    .open = [](const SinkRequest&, const SinkContext& ctx, const SinkStart& start,
               Sinks& out) { out.push_back(make_image_sink(ctx, start.saved != nullptr, start.first)); },
    .writes = [](std::string_view) { return false; },
    .join = nullptr,
    .refusal = "",
    .meaning = nullptr};

}  // namespace portalsim
