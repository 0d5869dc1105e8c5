#include "sink/coco.h"

#include <array>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "base/error.h"
#include "base/parallel.h"
#include "sink/output_folder.h"
#include "sink/sink_kinds.h"

namespace portalsim {

namespace fs = std::filesystem;
using nlohmann::json;

uint64_t coco_image_id(uint64_t index, size_t views, size_t view) { return index * views + view + 1; }
uint64_t coco_annotation_id(uint64_t image_id, int region) { return image_id * 16 + static_cast<uint64_t>(region); }

std::vector<uint32_t> coco_rle(const uint8_t* mask, int width, int height, uint8_t id, int bx, int by, int bw, int bh) {
  // Runs change only inside the box and where it meets the pixels around it; the
  // positions between are counted, not visited.
  std::vector<uint32_t> counts;
  bool inside = false;
  uint64_t last = 0;  // column-major position where the current run began
  const auto turn = [&](uint64_t at) {
    counts.push_back(static_cast<uint32_t>(at - last));
    last = at;
    inside = !inside;
  };
  const uint64_t H = static_cast<uint64_t>(height);
  for (int x = bx; x < bx + bw; ++x) {
    if (inside && by > 0) turn(x * H);  // the column's top, above the box, is off
    for (int y = by; y < by + bh; ++y)
      if ((mask[static_cast<size_t>(y) * width + x] == id) != inside) turn(x * H + static_cast<uint64_t>(y));
    if (inside && by + bh < height) turn(x * H + static_cast<uint64_t>(by + bh));
  }
  if (inside && bx + bw < width) turn(static_cast<uint64_t>(bx + bw) * H);
  counts.push_back(static_cast<uint32_t>(static_cast<uint64_t>(width) * H - last));
  return counts;
}

std::string yolo_lines(const ViewAnnotations& a, size_t scenario) {
  std::string s;
  char line[96];
  for (uint32_t k = a.first[scenario]; k < a.first[scenario + 1]; ++k) {
    const Annotation& t = a.items[k];
    std::snprintf(line, sizeof line, "%d %.6f %.6f %.6f %.6f\n", t.object, (t.x + t.w / 2.0) / a.width,
                  (t.y + t.h / 2.0) / a.height, static_cast<double>(t.w) / a.width,
                  static_cast<double>(t.h) / a.height);
    s += line;
  }
  return s;
}

namespace {

const char* const kImagesPart = ".portalsim/coco/images.json";
const char* const kAnnotationsPart = ".portalsim/coco/annotations.json";

class CocoSink final : public Sink {
 public:
  CocoSink(const SinkContext& ctx, const CocoOptions& opt, const std::map<std::string, FileState>* resume)
      : ctx_(ctx), opt_(opt) {
    std::error_code ec;
    fs::create_directories(fs::path(ctx.dir) / kStateDir / "coco", ec);
    if (ec) throw OutputError(ctx.dir + "/" + kStateDir + "/coco: cannot create: " + ec.message());
    const auto state = [&](const char* name) -> const FileState* {
      if (!resume) return nullptr;
      auto it = resume->find(name);
      if (it == resume->end()) throw OutputError(ctx.dir + "/.portalsim/checkpoint.json: no state for " + name);
      return &it->second;
    };
    images_ = std::make_unique<AppendFile>(ctx.dir, kImagesPart, state(kImagesPart));
    annotations_ = std::make_unique<AppendFile>(ctx.dir, kAnnotationsPart, state(kAnnotationsPart));
  }

  void write(const SceneBatch& scenes, const BatchOutput& out) override {
    // Records formatted in parallel chunks, each record after ",\n"; the file's very
    // first loses its comma.
    const size_t n = scenes.size();
    const unsigned parts = std::min<unsigned>(ctx_.threads, static_cast<unsigned>(std::max<size_t>(1, n / 64)));
    std::vector<std::string> im(std::max(1u, parts)), an(im.size());
    parallel_for(im.size(), parts, [&](size_t b, size_t e) {
      for (size_t c = b; c < e; ++c)
        for (size_t i = n * c / im.size(); i < n * (c + 1) / im.size(); ++i) records(scenes, out, i, im[c], an[c]);
    });
    append(*images_, im);
    append(*annotations_, an);
  }

  std::vector<FileState> files() const override {
    if (final_) return {*final_};
    return {images_->state(), annotations_->state()};
  }

  void finish() override {
    images_->finish();
    annotations_->finish();
    const fs::path dir(ctx_.dir), final_path = dir / "annotations.json", tmp = dir / "annotations.json.tmp";
    {
      std::ofstream o(tmp, std::ios::binary | std::ios::trunc);
      json categories = json::array();
      for (size_t c = 0; c < ctx_.cat->objects.size(); ++c)
        categories.push_back(
            {{"id", c + 1},
             {"name", ctx_.cat->objects[c].name},
             {"supercategory",
              ctx_.cat->objects[c].object_class.empty() ? std::string("object") : ctx_.cat->objects[c].object_class}});
      o << "{\"info\":" << opt_.info.dump() << ",\"licenses\":[],\"categories\":" << categories.dump()
        << ",\"images\":[";
      copy(o, dir / kImagesPart);
      o << "\n],\"annotations\":[";
      copy(o, dir / kAnnotationsPart);
      o << "\n]}\n";
      o.flush();
      if (!o) throw OutputError(tmp.string() + ": cannot write");
    }
    std::error_code ec;
    fs::rename(tmp, final_path, ec);
    if (ec) throw OutputError(final_path.string() + ": cannot move into place: " + ec.message());
    final_ = hash_file(ctx_.dir, "annotations.json");
  }

 private:
  SinkContext ctx_;
  CocoOptions opt_;
  std::unique_ptr<AppendFile> images_, annotations_;
  std::optional<FileState> final_;

  static void append(AppendFile& f, std::vector<std::string>& chunks) {
    bool first = f.size() == 0;
    for (std::string& c : chunks) {
      if (c.empty()) continue;
      f.append(first ? std::string_view(c).substr(1) : std::string_view(c));
      first = false;
    }
  }

  // Scenario i's image entries and annotations, as JSON text (portalsim's own keys last).
  void records(const SceneBatch& scenes, const BatchOutput& out, size_t i, std::string& im, std::string& an) const {
    const Catalogue& cat = *ctx_.cat;
    const size_t views = cat.sensors.size();
    const uint64_t index = scenes.first_index + i;
    const auto num = [](std::string& s, auto v) {
      char b[32];
      const auto r = std::to_chars(b, b + sizeof b, v);
      s.append(b, r.ptr);
    };
    const auto list = [&num](std::string& s, const auto& values) {  // [a,b,...]
      s += '[';
      for (auto v : values) {
        num(s, v);
        s += ',';
      }
      s.back() = ']';
    };
    for (size_t k = 0; k < views; ++k) {
      const ViewAnnotations& a = out.annotations[k];
      const Sensor& s = cat.sensors[k];
      const uint64_t image_id = coco_image_id(index, views, k);
      im += ",\n{\"id\":";
      num(im, image_id);
      im += ",\"file_name\":" + json(file_name(index, s.name)).dump() + ",\"width\":";
      num(im, s.width);
      im += ",\"height\":";
      num(im, s.height);
      im += ",\"scenario\":";
      num(im, index);
      im += ",\"view\":" + json(s.name).dump() + "}";
      for (uint32_t t = a.first[i]; t < a.first[i + 1]; ++t) {
        const Annotation& x = a.items[t];
        an += ",\n{\"id\":";
        num(an, coco_annotation_id(image_id, x.region));
        an += ",\"image_id\":";
        num(an, image_id);
        an += ",\"category_id\":";
        num(an, x.object + 1);
        an += ",\"bbox\":";
        list(an, std::array{x.x, x.y, x.w, x.h});
        an += ",\"area\":";
        num(an, x.area);
        an += ",\"iscrowd\":0,\"segmentation\":{\"counts\":";
        list(an, coco_rle(a.mask_of(i), a.width, a.height, static_cast<uint8_t>(x.region + 1), x.x, x.y, x.w, x.h));
        an += ",\"size\":[";
        num(an, a.height);
        an += ',';
        num(an, a.width);
        an += "]},\"region\":";
        num(an, x.region + 1);
        an += ",\"orientation\":" + json(cat.objects[x.object].variants[x.drawing].code).dump() + ",\"dx\":";
        num(an, x.dx);
        an += ",\"dy\":";
        num(an, x.dy);
        an += ",\"rotation\":";  // randomised objects: degrees counter-clockwise, factor, mirrored
        num(an, x.rotation);
        an += ",\"scale\":";
        num(an, x.scale);
        an += x.flip ? ",\"flip\":true}" : ",\"flip\":false}";
      }
    }
  }
  std::string file_name(uint64_t index, const std::string& view) const {
    if (!opt_.image_folder_ext.empty())
      return "images/" + image_folder_name(index) + "/" + view + "." + opt_.image_folder_ext;
    std::string f = opt_.tensor_file.empty() ? view + ".npy#" : opt_.tensor_file + "#" + view + "/";
    f += std::to_string(index);
    return f;
  }
  static void copy(std::ofstream& o, const fs::path& part) {
    std::error_code ec;
    if (fs::file_size(part, ec) == 0 && !ec) return;  // streaming an empty buffer would fail the stream
    std::ifstream in(part, std::ios::binary);
    if (!in) throw OutputError(part.string() + ": cannot read");
    o << in.rdbuf();
  }
};

}  // namespace

std::unique_ptr<Sink> make_coco_sink(const SinkContext& ctx, const CocoOptions& opt,
                                     const std::map<std::string, FileState>* resume) {
  return std::make_unique<CocoSink>(ctx, opt, resume);
}

// annotations.json (generate --annotations).
extern const SinkKind coco_kind{
    .name = "annotations.json",
    .flag = "--annotations",
    .formats = {},
    .format_help = "",
    .wanted = [](const SinkRequest& r) { return r.annotations; },
    .open =
        [](const SinkRequest& r, const SinkContext& ctx, const SinkStart& start, Sinks& out) {
          CocoOptions opt;
          if (!r.image_tensors) opt.image_folder_ext = r.image_format;
          if (r.has_format("h5")) opt.tensor_file = "data.h5";
          opt.info = {{"description", "portalsim"},
                      {"version", r.identity.at("portalsim")},
                      {"catalogue_hash", r.identity.at("catalogue").at("hash")},
                      {"spec", r.identity.at("spec")}};
          out.push_back(make_coco_sink(ctx, opt, start.saved));
        },
    .writes = [](std::string_view f) { return f == "annotations.json"; },
    .join = [](std::string_view) { return JoinAs::refused; },
    .refusal = "merge cannot join COCO annotations yet",
    .meaning =
        [](std::string_view, int, int) {
          return std::string(
              "COCO: categories, one image per scenario and camera view, and each object's box, area and run-length "
              "mask");
        }};

}  // namespace portalsim
