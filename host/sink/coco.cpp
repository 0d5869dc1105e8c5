#include "sink/coco.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "base/error.h"
#include "sink/output_folder.h"

namespace portalsim {

namespace fs = std::filesystem;
using nlohmann::json;

uint64_t coco_image_id(uint64_t index, size_t views, size_t view) { return index * views + view + 1; }
uint64_t coco_annotation_id(uint64_t image_id, int region) { return image_id * 16 + static_cast<uint64_t>(region); }

std::vector<uint32_t> coco_rle(const uint8_t* mask, int width, int height, uint8_t id) {
  std::vector<uint32_t> counts;
  bool inside = false;
  uint32_t run = 0;
  for (int x = 0; x < width; ++x)
    for (int y = 0; y < height; ++y) {
      const bool on = mask[static_cast<size_t>(y) * width + x] == id;
      if (on != inside) {
        counts.push_back(run);
        run = 0;
        inside = on;
      }
      ++run;
    }
  counts.push_back(run);
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
    const Catalogue& cat = *ctx_.cat;
    const size_t views = cat.sensors.size();
    std::string im, an;
    for (size_t i = 0; i < scenes.size(); ++i) {
      const uint64_t index = scenes.first_index + i;
      for (size_t k = 0; k < views; ++k) {
        const ViewAnnotations& a = out.annotations[k];
        const Sensor& s = cat.sensors[k];
        const uint64_t image_id = coco_image_id(index, views, k);
        json e = {{"id", image_id},    {"file_name", file_name(index, s.name)},
                  {"width", s.width},  {"height", s.height},
                  {"scenario", index}, {"view", s.name}};
        record(im, images_->state().bytes, e);
        for (uint32_t t = a.first[i]; t < a.first[i + 1]; ++t) {
          const Annotation& x = a.items[t];
          json r = {{"id", coco_annotation_id(image_id, x.region)},
                    {"image_id", image_id},
                    {"category_id", x.object + 1},
                    {"bbox", {x.x, x.y, x.w, x.h}},
                    {"area", x.area},
                    {"iscrowd", 0},
                    {"segmentation",
                     {{"counts", coco_rle(a.mask_of(i), a.width, a.height, static_cast<uint8_t>(x.region + 1))},
                      {"size", {a.height, a.width}}}},
                    {"region", x.region + 1},
                    {"orientation", cat.objects[x.object].variants[x.drawing].code},
                    {"dx", x.dx},
                    {"dy", x.dy}};
          record(an, annotations_->state().bytes, r);
        }
      }
    }
    images_->append(im);
    annotations_->append(an);
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
        categories.push_back({{"id", c + 1}, {"name", ctx_.cat->objects[c].name}, {"supercategory", "object"}});
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

  // Records are separated by commas: none before a file's first.
  static void record(std::string& buf, uint64_t bytes_before, const json& r) {
    buf += bytes_before == 0 && buf.empty() ? "\n" : ",\n";
    buf += r.dump();
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

}  // namespace portalsim
