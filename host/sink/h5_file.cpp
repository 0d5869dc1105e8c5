#include "sink/h5_file.h"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

#include "base/error.h"

namespace portalsim {

namespace fs = std::filesystem;

namespace {

// Each element type's size, .npy descriptor and HDF5 file and memory types.
struct TypeInfo {
  size_t size;
  const char* npy;
  hid_t file, memory;
};
TypeInfo type_info(TensorType t) {
  switch (t) {
    case TensorType::u8:
      break;
    case TensorType::i16:
      return {2, "<i2", H5T_STD_I16LE, H5T_NATIVE_INT16};
    case TensorType::f32:
      return {4, "<f4", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT};
    case TensorType::f64:
      return {8, "<f8", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE};
  }
  return {1, "|u1", H5T_STD_U8LE, H5T_NATIVE_UINT8};
}

}  // namespace

size_t type_size(TensorType t) { return type_info(t).size; }
const char* npy_descr(TensorType t) { return type_info(t).npy; }

size_t H5Dataset::row_bytes() const {
  size_t b = type_size(type);
  for (uint64_t d : dims) b *= d;
  return b;
}

namespace {

// HDF5 handles closed in reverse order on scope exit.
struct Ids {
  std::vector<std::pair<hid_t, herr_t (*)(hid_t)>> ids;
  hid_t keep(hid_t id, herr_t (*close)(hid_t)) {
    if (id >= 0) ids.emplace_back(id, close);
    return id;
  }
  ~Ids() {
    for (auto it = ids.rbegin(); it != ids.rend(); ++it) it->second(it->first);
  }
};

hid_t check(hid_t id, const std::string& path, const std::string& what) {
  if (id < 0) throw OutputError(path + ": HDF5 could not " + what);
  return id;
}

hid_t string_type(Ids& ids) {
  const hid_t type = ids.keep(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

void write_strings(hid_t obj, const H5Attribute& a, const std::string& path) {
  Ids ids;
  const hid_t type = string_type(ids);
  const hsize_t n = a.values.size();
  const hid_t space = ids.keep(a.scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
  std::vector<const char*> p;
  for (const std::string& v : a.values) p.push_back(v.c_str());
  const hid_t attr = ids.keep(H5Acreate2(obj, a.name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (attr < 0 || H5Awrite(attr, type, p.data()) < 0)
    throw OutputError(path + ": HDF5 could not write attribute " + a.name);
}

H5Attribute read_strings(hid_t obj, const char* name, const std::string& path) {
  Ids ids;
  const hid_t attr = ids.keep(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (attr < 0) throw InputError(path + ": attribute " + name + " cannot be opened");
  const hid_t space = ids.keep(H5Aget_space(attr), H5Sclose);
  const hid_t file_type = ids.keep(H5Aget_type(attr), H5Tclose);
  if (H5Tget_class(file_type) != H5T_STRING || !H5Tis_variable_str(file_type))
    throw InputError(path + ": attribute " + name + " is not a string attribute portalsim writes");
  H5Attribute a;
  a.name = name;
  a.scalar = H5Sget_simple_extent_ndims(space) == 0;
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  const hid_t type = string_type(ids);
  std::vector<char*> p(static_cast<size_t>(std::max<hssize_t>(n, 0)), nullptr);
  if (n < 0 || H5Aread(attr, type, p.data()) < 0) throw InputError(path + ": attribute " + name + " cannot be read");
  for (char* s : p) a.values.emplace_back(s ? s : "");
  H5Dvlen_reclaim(type, space, H5P_DEFAULT, p.data());
  return a;
}

// Creates `path` with the layout's attributes and datasets (no modification times
// anywhere: the file's bytes depend on the data alone) and calls `each(k, dataset)` while
// dataset k is open. Uncompressed datasets are contiguous, allocated at creation and never
// filled, so their rows can be written in place once the file is closed; compressed ones
// are chunked 64 rows along N, shuffled and gzipped, and `each` writes them.
void create_file(const std::string& path, const H5Layout& layout, const std::function<void(size_t, hid_t)>& each) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become OutputError below
  std::vector<H5Attribute> attributes = layout.attributes;
  H5Attribute names{"datasets", {}, false};
  for (const H5Dataset& d : layout.datasets) names.values.push_back(d.name);
  attributes.push_back(names);
  std::sort(attributes.begin(), attributes.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  Ids ids;
  const hid_t fcpl = ids.keep(check(H5Pcreate(H5P_FILE_CREATE), path, "make a property list"), H5Pclose);
  H5Pset_obj_track_times(fcpl, false);
  const hid_t file =
      ids.keep(check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT), path, "create the file"), H5Fclose);
  for (const H5Attribute& a : attributes) write_strings(file, a, path);
  for (size_t k = 0; k < layout.datasets.size(); ++k) {
    const H5Dataset& t = layout.datasets[k];
    std::vector<hsize_t> dims{layout.rows}, chunk{std::min<hsize_t>(64, std::max<hsize_t>(1, layout.rows))};
    for (uint64_t d : t.dims) {
      dims.push_back(d);
      chunk.push_back(d);
    }
    const std::string what = "create dataset " + t.name;
    Ids dset;
    const hid_t space =
        dset.keep(check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), path, what), H5Sclose);
    const hid_t dcpl = dset.keep(check(H5Pcreate(H5P_DATASET_CREATE), path, what), H5Pclose);
    H5Pset_obj_track_times(dcpl, false);
    if (layout.compress) {
      H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
      H5Pset_shuffle(dcpl);
      H5Pset_deflate(dcpl, 4);
    } else {
      H5Pset_layout(dcpl, H5D_CONTIGUOUS);
      H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);
      H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER);
    }
    const hid_t ds =
        dset.keep(check(H5Dcreate2(file, t.name.c_str(), type_info(t.type).file, space, H5P_DEFAULT, dcpl, H5P_DEFAULT),
                        path, what),
                  H5Dclose);
    if (!t.columns.empty()) write_strings(ds, H5Attribute{"columns", t.columns, false}, path);
    each(k, ds);
  }
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw OutputError(path + ": HDF5 could not flush the file");
}

// Where each dataset's rows start in the file (contiguous datasets only; 0 when empty).
uint64_t data_offset(hid_t ds, uint64_t bytes, const std::string& path, const std::string& name) {
  const haddr_t a = H5Dget_offset(ds);
  if (a == HADDR_UNDEF && bytes > 0) throw OutputError(path + ": dataset " + name + " has no contiguous storage");
  return a == HADDR_UNDEF ? 0 : static_cast<uint64_t>(a);
}

void sync_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    if (fd >= 0) ::close(fd);
    throw OutputError(path + ": cannot sync to disk");
  }
  ::close(fd);
}

}  // namespace

void write_at(int fd, const char* data, size_t n, uint64_t offset, const std::string& path) {
  while (n > 0) {
    const ssize_t w = ::pwrite(fd, data, n, static_cast<off_t>(offset));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw OutputError(path + ": write failed: " + std::strerror(w < 0 ? errno : ENOSPC));
    data += w;
    n -= static_cast<size_t>(w);
    offset += static_cast<uint64_t>(w);
  }
}

std::vector<uint64_t> create_h5_in_place(const std::string& path, const H5Layout& layout) {
  if (layout.compress) throw std::logic_error("create_h5_in_place: compressed datasets are written through HDF5");
  std::vector<uint64_t> offsets;
  create_file(path, layout, [&](size_t k, hid_t ds) {
    offsets.push_back(data_offset(ds, layout.rows * layout.datasets[k].row_bytes(), path, layout.datasets[k].name));
  });
  return offsets;
}

std::vector<uint64_t> h5_data_offsets(const std::string& path, const H5Layout& layout) {
  const H5Layout found = read_h5_layout(path);
  bool same = !found.compress && found.rows == layout.rows && found.datasets.size() == layout.datasets.size();
  for (size_t k = 0; same && k < found.datasets.size(); ++k)
    same = found.datasets[k].name == layout.datasets[k].name && found.datasets[k].type == layout.datasets[k].type &&
           found.datasets[k].dims == layout.datasets[k].dims;
  if (!same) throw OutputError(path + ": its datasets differ from this run's; the run cannot be resumed");
  Ids ids;
  const hid_t file = ids.keep(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file < 0) throw OutputError(path + ": HDF5 cannot open it");
  std::vector<uint64_t> offsets;
  for (const H5Dataset& t : layout.datasets) {
    Ids d;
    const hid_t ds = d.keep(H5Dopen2(file, t.name.c_str(), H5P_DEFAULT), H5Dclose);
    if (ds < 0) throw OutputError(path + ": dataset " + t.name + " is missing");
    offsets.push_back(data_offset(ds, layout.rows * t.row_bytes(), path, t.name));
  }
  return offsets;
}

void write_h5(const std::string& dir, const H5Layout& layout, const std::vector<std::string>& npy_paths) {
  const std::string final_path = (fs::path(dir) / "data.h5").string(), tmp = final_path + ".tmp";
  // Each dataset's rows from its .npy file (header skipped), in blocks of about 16 MiB.
  std::vector<char> buf;
  const auto copy_rows = [&](size_t k, const std::function<void(uint64_t first, size_t n)>& put) {
    const H5Dataset& t = layout.datasets[k];
    const std::string& src = npy_paths.at(k);
    std::ifstream in(src, std::ios::binary);
    char magic[10];
    if (!in.read(magic, sizeof magic)) throw OutputError(src + ": cannot read its .npy header");
    const size_t header = 10 + static_cast<unsigned char>(magic[8]) + 256u * static_cast<unsigned char>(magic[9]);
    in.seekg(static_cast<std::streamoff>(header));
    const size_t row = t.row_bytes(), block = std::max<size_t>(1, (16u << 20) / std::max<size_t>(1, row));
    for (uint64_t first = 0; first < layout.rows; first += block) {
      const size_t n = static_cast<size_t>(std::min<uint64_t>(block, layout.rows - first));
      buf.resize(n * row);
      if (!in.read(buf.data(), static_cast<std::streamsize>(buf.size())))
        throw OutputError(src + ": shorter than its " + std::to_string(layout.rows) + " rows");
      put(first, n);
    }
  };
  if (!layout.compress) {
    const std::vector<uint64_t> offsets = create_h5_in_place(tmp, layout);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw OutputError(tmp + ": cannot open: " + std::strerror(errno));
    try {
      for (size_t k = 0; k < layout.datasets.size(); ++k)
        copy_rows(k, [&](uint64_t first, size_t) {
          write_at(fd, buf.data(), buf.size(), offsets[k] + first * layout.datasets[k].row_bytes(), tmp);
        });
    } catch (...) {
      ::close(fd);
      throw;
    }
    ::close(fd);
  } else {
    create_file(tmp, layout, [&](size_t k, hid_t ds) {
      const H5Dataset& t = layout.datasets[k];
      std::vector<hsize_t> dims{layout.rows};
      dims.insert(dims.end(), t.dims.begin(), t.dims.end());
      copy_rows(k, [&](uint64_t first, size_t n) {
        std::vector<hsize_t> start(dims.size(), 0), count = dims;
        start[0] = first;
        count[0] = n;
        Ids io;
        const hid_t fspace = io.keep(check(H5Dget_space(ds), tmp, "write dataset " + t.name), H5Sclose);
        H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
        const hid_t mspace = io.keep(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), H5Sclose);
        if (H5Dwrite(ds, type_info(t.type).memory, mspace, fspace, H5P_DEFAULT, buf.data()) < 0)
          throw OutputError(tmp + ": HDF5 could not write dataset " + t.name + " (disk full?)");
      });
    });
  }
  sync_file(tmp);
  std::error_code ec;
  fs::rename(tmp, final_path, ec);
  if (ec) throw OutputError(final_path + ": cannot move into place: " + ec.message());
}

H5Layout read_h5_layout(const std::string& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  Ids ids;
  const hid_t file = ids.keep(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file < 0) throw InputError(path + ": not an HDF5 file HDF5 can open");
  H5Layout layout;
  std::vector<std::string> names;
  H5Aiterate2(
      file, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->push_back(name);
        return 0;
      },
      &names);
  std::vector<std::string> datasets;
  for (const std::string& n : names) {
    H5Attribute a = read_strings(file, n.c_str(), path);
    if (n == "datasets")
      datasets = a.values;
    else
      layout.attributes.push_back(std::move(a));
  }
  if (datasets.empty()) throw InputError(path + ": has no \"datasets\" attribute (not written by this portalsim)");
  for (size_t k = 0; k < datasets.size(); ++k) {
    const std::string& name = datasets[k];
    Ids d;
    const hid_t ds = d.keep(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (ds < 0) throw InputError(path + ": dataset " + name + " is missing");
    const hid_t type = d.keep(H5Dget_type(ds), H5Tclose);
    H5Dataset t;
    t.name = name;
    const H5T_class_t cls = H5Tget_class(type);
    const size_t size = H5Tget_size(type);
    if (cls == H5T_INTEGER && size == 1 && H5Tget_sign(type) == H5T_SGN_NONE)
      t.type = TensorType::u8;
    else if (cls == H5T_INTEGER && size == 2 && H5Tget_sign(type) == H5T_SGN_2)
      t.type = TensorType::i16;
    else if (cls == H5T_FLOAT && size == 4)
      t.type = TensorType::f32;
    else if (cls == H5T_FLOAT && size == 8)
      t.type = TensorType::f64;
    else
      throw InputError(path + ": dataset " + name + " has an element type portalsim does not write");
    const hid_t space = d.keep(H5Dget_space(ds), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space);
    if (rank < 1 || rank > 8) throw InputError(path + ": dataset " + name + " has rank " + std::to_string(rank));
    std::vector<hsize_t> dims(static_cast<size_t>(rank));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    if (k == 0) layout.rows = dims[0];
    if (dims[0] != layout.rows)
      throw InputError(path + ": dataset " + name + " has " + std::to_string(dims[0]) + " rows, not " +
                       std::to_string(layout.rows));
    t.dims.assign(dims.begin() + 1, dims.end());
    const hid_t dcpl = d.keep(H5Dget_create_plist(ds), H5Pclose);
    if (k == 0) layout.compress = H5Pget_nfilters(dcpl) > 0;
    if (H5Aexists(ds, "columns") > 0) t.columns = read_strings(ds, "columns", path).values;
    layout.datasets.push_back(std::move(t));
  }
  return layout;
}

void read_h5_rows(const std::string& path, const H5Dataset& t, uint64_t first, uint64_t n, char* out) {
  Ids ids;
  const hid_t file = ids.keep(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file < 0) throw InputError(path + ": cannot open");
  const hid_t ds = ids.keep(H5Dopen2(file, t.name.c_str(), H5P_DEFAULT), H5Dclose);
  if (ds < 0) throw InputError(path + ": dataset " + t.name + " is missing");
  std::vector<hsize_t> start(t.dims.size() + 1, 0), count{n};
  count.insert(count.end(), t.dims.begin(), t.dims.end());
  start[0] = first;
  const hid_t fspace = ids.keep(H5Dget_space(ds), H5Sclose);
  H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  const hid_t mspace = ids.keep(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), H5Sclose);
  if (H5Dread(ds, type_info(t.type).memory, mspace, fspace, H5P_DEFAULT, out) < 0)
    throw InputError(path + ": dataset " + t.name + ": cannot read rows " + std::to_string(first) + ".." +
                     std::to_string(first + n));
}

}  // namespace portalsim
