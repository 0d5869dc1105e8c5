#include "sink/tensors.h"

#include <hdf5.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include "base/error.h"
#include "base/parallel.h"
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

enum class Type { u8, i16, f32 };
size_t type_size(Type t) { return t == Type::u8 ? 1 : t == Type::i16 ? 2 : 4; }
const char* npy_descr(Type t) { return t == Type::u8 ? "|u1" : t == Type::i16 ? "<i2" : "<f4"; }

// One tensor: its name, element type, per-scenario shape and how a batch fills it.
struct Tensor {
  std::string name;
  Type type = Type::u8;
  std::vector<uint64_t> dims;  // after N
  std::function<void(const SceneBatch&, const BatchOutput&, std::string&)> fill;
  std::unique_ptr<AppendFile> file;
  size_t header = 0;
  size_t row_bytes() const {
    size_t b = type_size(type);
    for (uint64_t d : dims) b *= d;
    return b;
  }
};

// Throws OutputError naming the file when an HDF5 call fails.
hid_t check(hid_t id, const std::string& path, const std::string& what) {
  if (id < 0) throw OutputError(path + ": HDF5 could not " + what);
  return id;
}

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
          add(s.name, Type::u8, {h, w, 3}, [this, k](const SceneBatch& b, const BatchOutput& o, std::string& buf) {
            const ViewImages& v = o.views[k];
            const size_t px = v.pixels_per_image();
            buf.resize(b.size() * px * 3);
            for (size_t i = 0; i < b.size() * px; ++i)
              std::memcpy(&buf[i * 3], ctx_.assets->palette[v.pixels[i]].data(), 3);
          });
          add(s.name + "_index", Type::u8, {h, w}, [k](const SceneBatch&, const BatchOutput& o, std::string& buf) {
            buf.assign(reinterpret_cast<const char*>(o.views[k].pixels.data()), o.views[k].pixels.size());
          });
        } else {
          add(s.name, Type::u8, {h, w}, [k](const SceneBatch&, const BatchOutput& o, std::string& buf) {
            buf.assign(reinterpret_cast<const char*>(o.views[k].pixels.data()), o.views[k].pixels.size());
          });
        }
      }
    if (opt.features)
      add("features", Type::f32, {static_cast<uint64_t>(ctx.layout.image_features())},
          [](const SceneBatch&, const BatchOutput& o, std::string& buf) {
            buf.assign(reinterpret_cast<const char*>(o.features.data()), o.features.size() * sizeof(float));
          });
    if (opt.scenario) {
      add("metal", Type::u8, {kZones}, [](const SceneBatch&, const BatchOutput& o, std::string& buf) {
        buf.assign(reinterpret_cast<const char*>(o.metal.data()), o.metal.size());
      });
      add("label", Type::u8, {}, [](const SceneBatch& b, const BatchOutput&, std::string& buf) {
        buf.assign(reinterpret_cast<const char*>(b.label.data()), b.label.size());
      });
      add("subject", Type::u8, {}, [](const SceneBatch& b, const BatchOutput&, std::string& buf) {
        buf.resize(b.size());
        for (size_t i = 0; i < b.size(); ++i) buf[i] = static_cast<char>(b.subject[i] + 1);
      });
      add("region_object", Type::i16, {kRegions}, [this](const SceneBatch& b, const BatchOutput&, std::string& buf) {
        per_region(b, buf,
                   [&](int16_t v) { return v == kNoObject ? int16_t(-1) : int16_t(ctx_.cat->variant_list[v].object); });
      });
      add("region_orientation", Type::i16, {kRegions},
          [this](const SceneBatch& b, const BatchOutput&, std::string& buf) {
            per_region(b, buf, [&](int16_t v) {
              return v == kNoObject ? int16_t(-1) : int16_t(ctx_.cat->variant_list[v].variant);
            });
          });
      add("region_label", Type::u8, {kRegions}, [this](const SceneBatch& b, const BatchOutput&, std::string& buf) {
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
      const std::string file = file_name(t.name);
      const FileState* state = nullptr;
      if (resume) {
        auto it = resume->find(file);
        if (it == resume->end()) throw OutputError(ctx.dir + "/.portalsim/checkpoint.json: no state for " + file);
        state = &it->second;
      }
      std::vector<uint64_t> shape{ctx.rows};
      shape.insert(shape.end(), t.dims.begin(), t.dims.end());
      const std::string header = npy_array_header(npy_descr(t.type), shape);
      t.header = header.size();
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
  void add(const std::string& name, Type type, std::vector<uint64_t> dims,
           std::function<void(const SceneBatch&, const BatchOutput&, std::string&)> fill) {
    Tensor t;
    t.name = name;
    t.type = type;
    t.dims = std::move(dims);
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

  // data.h5 from the finished tensor files: written to data.h5.tmp, then renamed.
  void build_h5() {
    const fs::path dir(ctx_.dir);
    const std::string final_path = (dir / "data.h5").string(), tmp = final_path + ".tmp";
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become OutputError below
    {
      struct Ids {
        std::vector<std::pair<hid_t, herr_t (*)(hid_t)>> ids;
        hid_t keep(hid_t id, herr_t (*close)(hid_t)) {
          ids.emplace_back(id, close);
          return id;
        }
        ~Ids() {
          for (auto it = ids.rbegin(); it != ids.rend(); ++it) it->second(it->first);
        }
      } ids;
      // No modification times anywhere: the file's bytes depend on the data alone.
      const hid_t fcpl = ids.keep(check(H5Pcreate(H5P_FILE_CREATE), tmp, "make a property list"), H5Pclose);
      H5Pset_obj_track_times(fcpl, false);
      const hid_t file =
          ids.keep(check(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT), tmp, "create the file"), H5Fclose);
      write_attributes(file, tmp);
      std::vector<char> buf;
      for (const Tensor& t : tensors_) {
        std::vector<hsize_t> dims{ctx_.rows}, chunk{std::min<hsize_t>(64, std::max<hsize_t>(1, ctx_.rows))};
        for (uint64_t d : t.dims) {
          dims.push_back(d);
          chunk.push_back(d);
        }
        const std::string what = "write dataset " + t.name;
        const hid_t space = check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), tmp, what);
        const hid_t dcpl = check(H5Pcreate(H5P_DATASET_CREATE), tmp, what);
        H5Pset_obj_track_times(dcpl, false);
        H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
        if (opt_.compress) {
          H5Pset_shuffle(dcpl);
          H5Pset_deflate(dcpl, 4);
        }
        const hid_t type = t.type == Type::u8 ? H5T_STD_U8LE : t.type == Type::i16 ? H5T_STD_I16LE : H5T_IEEE_F32LE;
        const hid_t mem = t.type == Type::u8    ? H5T_NATIVE_UINT8
                          : t.type == Type::i16 ? H5T_NATIVE_INT16
                                                : H5T_NATIVE_FLOAT;
        const hid_t ds = H5Dcreate2(file, t.name.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
        H5Pclose(dcpl);
        H5Sclose(space);
        check(ds, tmp, what);
        ids.keep(ds, H5Dclose);
        if (t.name == "features") write_strings(ds, "columns", feature_names(), tmp);
        // Copy the rows over in blocks of about 16 MiB.
        const std::string src = (dir / file_name(t.name)).string();
        std::ifstream in(src, std::ios::binary);
        in.seekg(static_cast<std::streamoff>(t.header));
        const size_t row = t.row_bytes(), block = std::max<size_t>(1, (16u << 20) / row);
        for (uint64_t first = 0; first < ctx_.rows; first += block) {
          const size_t n = static_cast<size_t>(std::min<uint64_t>(block, ctx_.rows - first));
          buf.resize(n * row);
          if (!in.read(buf.data(), static_cast<std::streamsize>(buf.size())))
            throw OutputError(src + ": shorter than its " + std::to_string(ctx_.rows) + " rows");
          std::vector<hsize_t> start(dims.size(), 0), count = dims;
          start[0] = first;
          count[0] = n;
          const hid_t fspace = check(H5Dget_space(ds), tmp, what);
          H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
          const hid_t mspace = H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr);
          const herr_t w = H5Dwrite(ds, mem, mspace, fspace, H5P_DEFAULT, buf.data());
          H5Sclose(mspace);
          H5Sclose(fspace);
          if (w < 0) throw OutputError(tmp + ": HDF5 could not " + what + " (disk full?)");
        }
      }
      if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw OutputError(tmp + ": HDF5 could not flush the file");
    }
    // Closed (the Ids destructor); now durable, then in place.
    {
      std::FILE* f = std::fopen(tmp.c_str(), "rb+");
      if (!f || ::fsync(fileno(f)) != 0) {
        if (f) std::fclose(f);
        throw OutputError(tmp + ": cannot sync to disk");
      }
      std::fclose(f);
    }
    std::error_code ec;
    fs::rename(tmp, final_path, ec);
    if (ec) throw OutputError(final_path + ": cannot move into place: " + ec.message());
    h5_state_ = hash_file(ctx_.dir, "data.h5");
  }

  std::vector<std::string> feature_names() const {
    std::vector<std::string> n = ctx_.layout.names();
    n.resize(static_cast<size_t>(ctx_.layout.image_features()));
    return n;
  }

  // A variable-length UTF-8 string attribute: scalar, or a 1-d array of them.
  static void write_strings(hid_t obj, const char* name, const std::vector<std::string>& values,
                            const std::string& path, bool scalar = false) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    const hsize_t n = values.size();
    const hid_t space = scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
    std::vector<const char*> p;
    for (const std::string& v : values) p.push_back(v.c_str());
    const hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    const herr_t w = attr < 0 ? -1 : H5Awrite(attr, type, p.data());
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
    if (w < 0) throw OutputError(path + ": HDF5 could not write attribute " + name);
  }
  static void write_string(hid_t obj, const char* name, const std::string& value, const std::string& path) {
    write_strings(obj, name, {value}, path, true);
  }

  void write_attributes(hid_t file, const std::string& path) {
    const Catalogue& cat = *ctx_.cat;
    write_string(file, "portalsim", opt_.identity.value("portalsim", std::string()), path);
    write_string(file, "catalogue_hash", cat.hash, path);
    write_string(file, "spec", opt_.identity.value("spec", nlohmann::json::object()).dump(), path);
    write_string(file, "identity", opt_.identity.dump(), path);
    write_strings(file, "class_names", {"negative", "positive"}, path);
    std::vector<std::string> objects, regions, drawings;
    for (const Object& o : cat.objects) {
      objects.push_back(o.name);
      std::string codes;  // region_orientation indexes these: "h,v", or "" for one drawing
      for (const Variant& v : o.variants) codes += (codes.empty() ? "" : ",") + v.code;
      drawings.push_back(codes);
    }
    for (const Region& r : cat.regions) regions.push_back(r.name);
    write_strings(file, "object_names", objects, path);
    write_strings(file, "region_names", regions, path);
    write_strings(file, "object_drawings", drawings, path);
    write_string(file, "region_label_rule", opt_.rule ? opt_.rule->text() : std::string(), path);
  }
};

}  // namespace

std::unique_ptr<Sink> make_tensor_sink(const SinkContext& ctx, const TensorOptions& opt,
                                       const std::map<std::string, FileState>* resume) {
  return std::make_unique<TensorSink>(ctx, opt, resume);
}

}  // namespace portalsim
