#include "sink/tensors.h"

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include "base/error.h"
#include "base/parallel.h"
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

// One tensor: its dataset description and how a batch fills it.
struct Tensor {
  H5Dataset ds;
  std::function<void(const SceneBatch&, const BatchOutput&, std::string&)> fill;
  std::unique_ptr<AppendFile> file;
};

class TensorSink final : public Sink {
 public:
  TensorSink(const SinkContext& ctx, const TensorOptions& opt, const std::map<std::string, FileState>* resume)
      : ctx_(ctx), opt_(opt) {
    const Catalogue& cat = *ctx.cat;
    if (opt.h5) {
      std::error_code ec;
      fs::create_directories(fs::path(ctx.dir) / kStateDir / "tensors", ec);
      if (ec) throw OutputError(ctx.dir + "/" + kStateDir + "/tensors: cannot create: " + ec.message());
    }
    if (opt.images)
      for (size_t k = 0; k < cat.sensors.size(); ++k) {
        const Sensor& s = cat.sensors[k];
        const uint64_t h = static_cast<uint64_t>(s.height), w = static_cast<uint64_t>(s.width);
        if (s.palette) {
          add(s.name, TensorType::u8, {h, w, 3},
              [this, k](const SceneBatch& b, const BatchOutput& o, std::string& buf) {
                const ViewImages& v = o.views[k];
                const size_t px = v.pixels_per_image();
                buf.resize(b.size() * px * 3);
                for (size_t i = 0; i < b.size() * px; ++i)
                  std::memcpy(&buf[i * 3], ctx_.palette[v.pixels[i]].data(), 3);
              });
          add(s.name + "_index", TensorType::u8, {h, w},
              [k](const SceneBatch&, const BatchOutput& o, std::string& buf) {
                buf.assign(reinterpret_cast<const char*>(o.views[k].pixels.data()), o.views[k].pixels.size());
              });
        } else {
          add(s.name, TensorType::u8, {h, w}, [k](const SceneBatch&, const BatchOutput& o, std::string& buf) {
            buf.assign(reinterpret_cast<const char*>(o.views[k].pixels.data()), o.views[k].pixels.size());
          });
        }
      }
    if (opt.annotations)
      for (size_t k = 0; k < cat.sensors.size(); ++k) {
        const Sensor& s = cat.sensors[k];
        add("mask_" + s.name, TensorType::u8, {static_cast<uint64_t>(s.height), static_cast<uint64_t>(s.width)},
            [k](const SceneBatch&, const BatchOutput& o, std::string& buf) {
              buf.assign(reinterpret_cast<const char*>(o.annotations[k].masks.data()), o.annotations[k].masks.size());
            });
      }
    if (opt.features)
      add("features", TensorType::f32, {static_cast<uint64_t>(ctx.layout.image_features())},
          [](const SceneBatch&, const BatchOutput& o, std::string& buf) {
            buf.assign(reinterpret_cast<const char*>(o.features.data()), o.features.size() * sizeof(float));
          });
    if (opt.scenario) {
      add("metal", TensorType::u8, {kZones}, [](const SceneBatch&, const BatchOutput& o, std::string& buf) {
        buf.assign(reinterpret_cast<const char*>(o.metal.data()), o.metal.size());
      });
      add("label", TensorType::u8, {}, [](const SceneBatch& b, const BatchOutput&, std::string& buf) {
        buf.assign(reinterpret_cast<const char*>(b.label.data()), b.label.size());
      });
      add("subject", TensorType::u8, {}, [](const SceneBatch& b, const BatchOutput&, std::string& buf) {
        buf.resize(b.size());
        for (size_t i = 0; i < b.size(); ++i) buf[i] = static_cast<char>(b.subject[i] + 1);
      });
      add("region_object", TensorType::i16, {kRegions},
          [this](const SceneBatch& b, const BatchOutput&, std::string& buf) {
            per_region(b, buf, [&](int16_t v) {
              return v == kNoObject ? int16_t(-1) : int16_t(ctx_.cat->variant_list[v].object);
            });
          });
      add("region_orientation", TensorType::i16, {kRegions},
          [this](const SceneBatch& b, const BatchOutput&, std::string& buf) {
            per_region(b, buf, [&](int16_t v) {
              return v == kNoObject ? int16_t(-1) : int16_t(ctx_.cat->variant_list[v].variant);
            });
          });
      add("region_label", TensorType::u8, {kRegions},
          [this](const SceneBatch& b, const BatchOutput&, std::string& buf) {
            buf.assign(b.size() * kRegions, '\0');
            if (!opt_.rule) return;
            for (size_t i = 0; i < b.size(); ++i)
              for (int r = 0; r < kRegions; ++r) {
                const int16_t v = b.objects[i * kRegions + r];
                if (v == kNoObject) continue;
                Scenario alone;
                alone.subject = b.subject[i];
                alone.objects[r] = v;
                buf[i * kRegions + r] = (*opt_.rule)(alone) ? 1 : 0;
              }
          });
    }
    for (Tensor& t : tensors_) {
      const std::string file = file_name(t.ds.name);
      const FileState* state = nullptr;
      if (resume) {
        auto it = resume->find(file);
        if (it == resume->end()) throw OutputError(ctx.dir + "/.portalsim/checkpoint.json: no state for " + file);
        state = &it->second;
      }
      std::vector<uint64_t> shape{ctx.rows};
      shape.insert(shape.end(), t.ds.dims.begin(), t.ds.dims.end());
      const std::string header = npy_array_header(npy_descr(t.ds.type), shape);
      t.file = std::make_unique<AppendFile>(ctx.dir, file, state);
      if (!state) t.file->append(header);
    }
  }

  void write(const SceneBatch& scenes, const BatchOutput& out) override {
    std::vector<std::string> bufs(tensors_.size());
    parallel_for(tensors_.size(), std::min<unsigned>(ctx_.threads, static_cast<unsigned>(tensors_.size())),
                 [&](size_t b, size_t e) {
                   for (size_t k = b; k < e; ++k) tensors_[k].fill(scenes, out, bufs[k]);
                 });
    for (size_t k = 0; k < tensors_.size(); ++k) tensors_[k].file->append(bufs[k]);
  }

  std::vector<FileState> files() const override {
    if (h5_state_) return {*h5_state_};
    std::vector<FileState> f;
    for (const Tensor& t : tensors_) f.push_back(t.file->state());
    return f;
  }

  void finish() override {
    for (Tensor& t : tensors_) t.file->finish();
    if (opt_.h5) build_h5();
  }

 private:
  SinkContext ctx_;
  TensorOptions opt_;
  std::vector<Tensor> tensors_;
  std::optional<FileState> h5_state_;

  std::string file_name(const std::string& tensor) const {
    return opt_.h5 ? std::string(kStateDir) + "/tensors/" + tensor + ".npy" : tensor + ".npy";
  }
  void add(const std::string& name, TensorType type, std::vector<uint64_t> dims,
           std::function<void(const SceneBatch&, const BatchOutput&, std::string&)> fill) {
    Tensor t;
    t.ds.name = name;
    t.ds.type = type;
    t.ds.dims = std::move(dims);
    if (name == "features") t.ds.columns = feature_names();
    t.fill = std::move(fill);
    tensors_.push_back(std::move(t));
  }
  template <class F>
  static void per_region(const SceneBatch& b, std::string& buf, F f) {
    buf.resize(b.size() * kRegions * sizeof(int16_t));
    for (size_t i = 0; i < b.size() * kRegions; ++i) {
      const int16_t v = f(b.objects[i]);
      std::memcpy(&buf[i * sizeof(int16_t)], &v, sizeof v);
    }
  }

  // data.h5 from the finished tensor files.
  void build_h5() {
    H5Layout layout;
    layout.rows = ctx_.rows;
    layout.compress = opt_.compress;
    layout.attributes = attributes();
    std::vector<std::string> paths;
    for (const Tensor& t : tensors_) {
      layout.datasets.push_back(t.ds);
      paths.push_back((fs::path(ctx_.dir) / file_name(t.ds.name)).string());
    }
    write_h5(ctx_.dir, layout, paths);
    h5_state_ = hash_file(ctx_.dir, "data.h5");
  }

  std::vector<std::string> feature_names() const {
    std::vector<std::string> n = ctx_.layout.names();
    n.resize(static_cast<size_t>(ctx_.layout.image_features()));
    return n;
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
        drawings{"object_drawings", {}, false};
    for (const Object& o : cat.objects) {
      objects.values.push_back(o.name);
      std::string codes;  // region_orientation indexes these: "h,v", or "" for one drawing
      for (const Variant& v : o.variants) codes += (codes.empty() ? "" : ",") + v.code;
      drawings.values.push_back(codes);
    }
    for (const Region& r : cat.regions) regions.values.push_back(r.name);
    a.push_back(objects);
    a.push_back(regions);
    a.push_back(drawings);
    a.push_back({"region_label_rule", {opt_.rule ? opt_.rule->text() : std::string()}, true});
    return a;
  }
};

}  // namespace

std::unique_ptr<Sink> make_tensor_sink(const SinkContext& ctx, const TensorOptions& opt,
                                       const std::map<std::string, FileState>* resume) {
  return std::make_unique<TensorSink>(ctx, opt, resume);
}

}  // namespace portalsim
