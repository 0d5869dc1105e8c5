#include "sink/h5_file.h"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

#include "base/error.h"
#include "base/sizes.h"
#include "io/contained.h"

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

// Where the chunk holding row `row` of dataset `d` (open as `ds`) is, as HDF5's chunk index
// says (a pass over the index). Throws OutputError naming `path`.
uint64_t chunk_address(hid_t ds, const H5Dataset& d, uint64_t row, const std::string& path) {
  std::vector<hsize_t> origin(d.dims.size() + 1, 0);
  origin[0] = row;
  unsigned filter_mask = 0;
  haddr_t addr = HADDR_UNDEF;
  hsize_t size = 0;
  if (ds < 0 || H5Dget_chunk_info_by_coord(ds, origin.data(), &filter_mask, &addr, &size) < 0 || addr == HADDR_UNDEF)
    throw OutputError(path + ": HDF5 cannot say where the chunk of row " + std::to_string(row) + " of dataset " +
                      d.name + " is");
  return static_cast<uint64_t>(addr);
}

// Creates `path` with the layout's attributes and datasets (no modification times
// anywhere: the file's bytes depend on the data alone), chunked kH5ChunkRows along N. With
// `place` (uncompressed) every chunk is allocated here and never filled, chunk c of every
// dataset before chunk c + 1 of any, and `place` says where; the rows are written in place
// once the file is closed. Compressed, chunks are shuffled and gzipped, and `each(k,
// dataset)` writes dataset k while it is open.
void create_file(const std::string& path, const H5Layout& layout, const std::function<void(size_t, hid_t)>& each,
                 H5InPlace* place, std::vector<std::pair<size_t, uint64_t>>* guessed = nullptr) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become OutputError below
  std::vector<H5Attribute> attributes = layout.attributes;
  H5Attribute names{"datasets", {}, false};
  for (const H5Dataset& d : layout.datasets) names.values.push_back(d.name);
  attributes.push_back(names);
  std::sort(attributes.begin(), attributes.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  Ids ids;
  const hid_t fcpl = ids.keep(check(H5Pcreate(H5P_FILE_CREATE), path, "make a property list"), H5Pclose);
  H5Pset_obj_track_times(fcpl, false);
  const hid_t fapl = ids.keep(check(H5Pcreate(H5P_FILE_ACCESS), path, "make a property list"), H5Pclose);
  if (place) {
    // Each allocation at the end of the file, in the order made: no blocks of small chunks
    // or of metadata set aside ahead, which would put a chunk far from its neighbours. And
    // chunk index nodes of 1,024 chunks (32 by default): a node split is the metadata that
    // makes create_file ask HDF5 where a chunk went, and asking costs a pass over the index
    // (1M rows: 112 asks instead of 1,911).
    H5Pset_small_data_block_size(fapl, 0);
    H5Pset_meta_block_size(fapl, 0);
    H5Pset_istore_k(fcpl, 512);
  }
  const hid_t file =
      ids.keep(check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, fapl), path, "create the file"), H5Fclose);
  for (const H5Attribute& a : attributes) write_strings(file, a, path);
  const hsize_t chunk_rows = std::min<hsize_t>(kH5ChunkRows, std::max<hsize_t>(1, layout.rows));
  std::vector<hid_t> open;  // in place: every dataset, kept open to allocate its chunks
  for (size_t k = 0; k < layout.datasets.size(); ++k) {
    const H5Dataset& t = layout.datasets[k];
    std::vector<hsize_t> dims{layout.rows}, max{layout.rows}, chunk{chunk_rows};
    if (place) dims[0] = std::min<hsize_t>(chunk_rows, layout.rows);  // grown a chunk at a time below
    for (uint64_t d : t.dims) {
      dims.push_back(d);
      max.push_back(d);
      chunk.push_back(d);
    }
    const std::string what = "create dataset " + t.name;
    Ids dset;
    const hid_t space = dset.keep(
        check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), place ? max.data() : nullptr), path, what),
        H5Sclose);
    const hid_t dcpl = dset.keep(check(H5Pcreate(H5P_DATASET_CREATE), path, what), H5Pclose);
    H5Pset_obj_track_times(dcpl, false);
    H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
    if (layout.compress) {
      H5Pset_shuffle(dcpl);
      H5Pset_deflate(dcpl, 4);
    } else {
      H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);
      H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER);
    }
    const hid_t ds = check(
        H5Dcreate2(file, t.name.c_str(), type_info(t.type).file, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), path, what);
    if (place) {
      ids.keep(ds, H5Dclose);
      open.push_back(ds);
    } else {
      dset.keep(ds, H5Dclose);
    }
    if (!t.columns.empty()) write_strings(ds, H5Attribute{"columns", t.columns, false}, path);
    if (each) each(k, ds);
  }
  if (place) {
    // Chunk c of each dataset in turn, each allocated (at the end of the file) as its
    // dataset grows over it. Its address is where the file ended before: when the file grew
    // by more (HDF5 also placed an index node, after the chunk), that is checked once the
    // file is closed (create_h5_in_place); when by less, HDF5 is asked (a pass over the
    // chunk index, so not for every guess).
    const uint64_t chunks = (layout.rows + chunk_rows - 1) / chunk_rows;
    place->chunk_rows = chunk_rows;
    place->address.assign(layout.datasets.size(), std::vector<uint64_t>(chunks, 0));
    const auto ask = [&](size_t k, uint64_t c) {
      return chunk_address(open[k], layout.datasets[k], c * chunk_rows, path);
    };
    for (uint64_t c = 0; c < chunks; ++c)
      for (size_t k = 0; k < layout.datasets.size(); ++k) {
        if (c == 0) {
          place->address[k][c] = ask(k, c);
          continue;
        }
        const H5Dataset& t = layout.datasets[k];
        std::vector<hsize_t> dims{std::min<uint64_t>(layout.rows, (c + 1) * chunk_rows)};
        dims.insert(dims.end(), t.dims.begin(), t.dims.end());
        haddr_t before = 0, after = 0;
        if (H5Fget_eoa(file, &before) < 0 || H5Dset_extent(open[k], dims.data()) < 0 || H5Fget_eoa(file, &after) < 0)
          throw OutputError(path + ": HDF5 could not allocate dataset " + t.name + " (disk full?)");
        const uint64_t grew = after - before, bytes = chunk_rows * t.row_bytes();
        place->address[k][c] = grew < bytes ? ask(k, c) : before;
        if (grew > bytes) guessed->emplace_back(k, c);
      }
  }
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw OutputError(path + ": HDF5 could not flush the file");
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

void read_at(int fd, char* data, size_t n, uint64_t offset, const std::string& path, const char* what) {
  while (n > 0) {
    const ssize_t r = ::pread(fd, data, n, static_cast<off_t>(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw OutputError(path + ": cannot read back " + what + ": " + std::strerror(r < 0 ? errno : EIO));
    data += r;
    n -= static_cast<size_t>(r);
    offset += static_cast<uint64_t>(r);
  }
}

namespace {

uint64_t size_of_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw OutputError(path + ": cannot stat: " + std::strerror(errno));
  return static_cast<uint64_t>(st.st_size);
}

// chunk_address, with the closed file `path` opened again.
uint64_t ask_chunk_address(const std::string& path, const H5Layout& layout, size_t k, uint64_t row) {
  Ids ids;
  const hid_t file = ids.keep(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  const hid_t ds = file < 0 ? -1 : ids.keep(H5Dopen2(file, layout.datasets[k].name.c_str(), H5P_DEFAULT), H5Dclose);
  return chunk_address(ds, layout.datasets[k], row, path);
}

}  // namespace

H5InPlace create_h5_in_place(const std::string& path, const H5Layout& layout) {
  if (layout.compress) throw std::logic_error("create_h5_in_place: compressed datasets are written through HDF5");
  // The whole file is allocated up front (and filled as the run goes): refuse one larger
  // than the filesystem it is on, before laying out millions of chunks for it.
  const uint64_t chunk_rows = std::min<uint64_t>(kH5ChunkRows, std::max<uint64_t>(1, layout.rows));
  const uint64_t chunks = (layout.rows + chunk_rows - 1) / chunk_rows;
  uint64_t total = 0;
  bool overflow = false;
  for (const H5Dataset& t : layout.datasets) {
    uint64_t b = 0;
    overflow |= __builtin_mul_overflow(chunks * chunk_rows, static_cast<uint64_t>(t.row_bytes()), &b);
    overflow |= __builtin_add_overflow(total, b, &total);
  }
  struct statvfs fs_info {};
  const std::string dir = fs::path(path).parent_path().string();
  if (::statvfs(dir.empty() ? "." : dir.c_str(), &fs_info) == 0) {
    const unsigned __int128 capacity = static_cast<unsigned __int128>(fs_info.f_blocks) * fs_info.f_frsize;
    if (overflow || total > capacity)
      throw OutputError(path + ": " + std::to_string(layout.rows) + " rows would take " +
                        (overflow ? std::string("more than 2^64") : std::to_string(total)) +
                        " bytes, more than the whole filesystem holds (" +
                        std::to_string(static_cast<uint64_t>(std::min<unsigned __int128>(capacity, UINT64_MAX))) +
                        " bytes); make fewer scenarios per run (--shard), or write elsewhere");
  }
  H5InPlace place;
  std::vector<std::pair<size_t, uint64_t>> guessed;
  create_file(path, layout, nullptr, &place, &guessed);
  place.file_size = size_of_file(path);
  // A chunk placed with metadata after it: its first bytes were never written (zeros) and
  // the metadata right after it begins with a signature (never zero). Else HDF5 is asked.
  if (!guessed.empty()) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw OutputError(path + ": cannot open: " + std::strerror(errno));
    for (const auto& [k, c] : guessed) {
      const uint64_t at = place.address[k][c], bytes = place.chunk_rows * layout.datasets[k].row_bytes();
      unsigned char head[8] = {}, next[4] = {};
      const bool chunk_here =
          ::pread(fd, head, sizeof head, static_cast<off_t>(at)) == static_cast<ssize_t>(sizeof head) &&
          ::pread(fd, next, sizeof next, static_cast<off_t>(at + bytes)) == static_cast<ssize_t>(sizeof next) &&
          std::all_of(head, head + sizeof head, [](unsigned char b) { return b == 0; }) &&
          std::any_of(next, next + sizeof next, [](unsigned char b) { return b != 0; });
      if (!chunk_here) place.address[k][c] = ask_chunk_address(path, layout, k, c * place.chunk_rows);
    }
    ::close(fd);
  }
  // The order the writer and its file-order hash rely on, checked.
  uint64_t end = 0;
  for (uint64_t c = 0; c < chunks; ++c)
    for (size_t k = 0; k < layout.datasets.size(); ++k) {
      if (place.address[k][c] < end)
        throw OutputError(path + ": HDF5 placed chunk " + std::to_string(c) + " of dataset " + layout.datasets[k].name +
                          " out of order");
      end = place.address[k][c] + place.chunk_rows * layout.datasets[k].row_bytes();
    }
  if (end > place.file_size) throw OutputError(path + ": shorter than the chunks HDF5 allocated in it");
  return place;
}

H5InPlace h5_in_place_layout(const std::string& path, const H5Layout& layout, const std::string& scratch) {
  const H5Layout found = read_h5_layout(path);
  bool same = !found.compress && found.rows == layout.rows && found.datasets.size() == layout.datasets.size();
  for (size_t k = 0; same && k < found.datasets.size(); ++k)
    same = found.datasets[k].name == layout.datasets[k].name && found.datasets[k].type == layout.datasets[k].type &&
           found.datasets[k].dims == layout.datasets[k].dims;
  if (!same) throw OutputError(path + ": its datasets differ from this run's; the run cannot be resumed");
  // Laid out again (the layout is a function of `layout` alone), and compared outside the
  // chunks, byte for byte: the same metadata means the same chunk addresses.
  H5InPlace place;
  struct Remove {
    std::string path;
    ~Remove() {
      std::error_code ec;
      fs::remove(path, ec);
    }
  } remove{scratch};
  try {
    place = create_h5_in_place(scratch, layout);
  } catch (const OutputError& e) {
    throw OutputError(path + ": cannot lay this run's data.h5 out again to compare: " + e.what());
  }
  const auto differs = [&] {
    return OutputError(path + ": its layout differs from this run's; the run cannot be resumed");
  };
  if (size_of_file(path) != place.file_size) throw differs();
  std::vector<std::pair<uint64_t, uint64_t>> chunks;  // [address, end)
  for (size_t k = 0; k < layout.datasets.size(); ++k)
    for (uint64_t a : place.address[k]) chunks.emplace_back(a, a + place.chunk_rows * layout.datasets[k].row_bytes());
  std::sort(chunks.begin(), chunks.end());
  chunks.emplace_back(place.file_size, place.file_size);
  std::ifstream a(path, std::ios::binary), b(scratch, std::ios::binary);
  std::string x, y;
  uint64_t from = 0;
  for (const auto& [start, end] : chunks) {
    if (start > from) {
      x.resize(start - from);
      y.resize(start - from);
      a.seekg(static_cast<std::streamoff>(from));
      b.seekg(static_cast<std::streamoff>(from));
      if (!a.read(x.data(), static_cast<std::streamsize>(x.size())) ||
          !b.read(y.data(), static_cast<std::streamsize>(y.size())) || x != y)
        throw differs();
    }
    from = std::max(from, end);
  }
  return place;
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
    const size_t row = t.row_bytes(), block = std::max<size_t>(1, kIoPieceBytes / std::max<size_t>(1, row));
    for (uint64_t first = 0; first < layout.rows; first += block) {
      const size_t n = static_cast<size_t>(std::min<uint64_t>(block, layout.rows - first));
      buf.resize(n * row);
      if (!in.read(buf.data(), static_cast<std::streamsize>(buf.size())))
        throw OutputError(src + ": shorter than its " + std::to_string(layout.rows) + " rows");
      put(first, n);
    }
  };
  if (!layout.compress) {
    const H5InPlace place = create_h5_in_place(tmp, layout);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw OutputError(tmp + ": cannot open: " + std::strerror(errno));
    try {
      for (size_t k = 0; k < layout.datasets.size(); ++k)
        copy_rows(k, [&](uint64_t first, size_t n) {
          const size_t row = layout.datasets[k].row_bytes();
          for (uint64_t r = first; r < first + n;) {  // a chunk at a time
            const uint64_t to = std::min<uint64_t>(first + n, (r / place.chunk_rows + 1) * place.chunk_rows);
            write_at(fd, buf.data() + (r - first) * row, (to - r) * row, place.at(k, r, row), tmp);
            r = to;
          }
        });
    } catch (...) {
      ::close(fd);
      throw;
    }
    ::close(fd);
  } else {
    create_file(
        tmp, layout,
        [&](size_t k, hid_t ds) {
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
            const hid_t mspace =
                io.keep(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), H5Sclose);
            if (H5Dwrite(ds, type_info(t.type).memory, mspace, fspace, H5P_DEFAULT, buf.data()) < 0)
              throw OutputError(tmp + ": HDF5 could not write dataset " + t.name + " (disk full?)");
          });
        },
        nullptr);
  }
  sync_file(tmp);
  std::error_code ec;
  fs::rename(tmp, final_path, ec);
  if (ec) throw OutputError(final_path + ": cannot move into place: " + ec.message());
}

namespace {

// The two readers below run in a child (io::read_contained): libhdf5 1.10.8 reads past a
// heap buffer on some corrupt files (tests/fuzz/crashes/h5/), and any data.h5 may be foreign.
H5Layout layout_here(const std::string& path) {
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

void rows_here(const std::string& path, const H5Dataset& t, uint64_t first, uint64_t n, char* out) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
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

void pack(io::Packer& p, const H5Layout& l) {
  p.u64(l.rows);
  p.u64(l.compress);
  p.u64(l.attributes.size());
  for (const H5Attribute& a : l.attributes) {
    p.str(a.name);
    p.strs(a.values);
    p.u64(a.scalar);
  }
  p.u64(l.datasets.size());
  for (const H5Dataset& d : l.datasets) {
    p.str(d.name);
    p.u64(static_cast<uint64_t>(d.type));
    p.u64(d.dims.size());
    for (uint64_t v : d.dims) p.u64(v);
    p.strs(d.columns);
  }
}

H5Layout unpack(io::Unpacker& u) {
  H5Layout l;
  l.rows = u.u64();
  l.compress = u.u64() != 0;
  l.attributes.resize(u.u64());
  for (H5Attribute& a : l.attributes) {
    a.name = u.str();
    a.values = u.strs();
    a.scalar = u.u64() != 0;
  }
  l.datasets.resize(u.u64());
  for (H5Dataset& d : l.datasets) {
    d.name = u.str();
    d.type = static_cast<TensorType>(u.u64());
    d.dims.resize(u.u64());
    for (uint64_t& v : d.dims) v = u.u64();
    d.columns = u.strs();
  }
  return l;
}

}  // namespace

H5Layout read_h5_layout(const std::string& path) {
  const std::string bytes = io::read_contained(path, "libhdf5", [&] {
    io::Packer p;
    pack(p, layout_here(path));
    return p.bytes;
  });
  io::Unpacker u(bytes);
  H5Layout l = unpack(u);
  if (!u.done()) throw std::runtime_error(path + ": the contained reader sent back more than a layout");
  return l;
}

void read_h5_rows(const std::string& path, const H5Dataset& t, uint64_t first, uint64_t n, char* out) {
  const size_t bytes = static_cast<size_t>(n * t.row_bytes());
  const std::string rows = io::read_contained(path, "libhdf5", [&] {
    std::string b(bytes, '\0');
    rows_here(path, t, first, n, b.data());
    return b;
  });
  if (rows.size() != bytes) throw std::runtime_error(path + ": the contained reader sent back the wrong row count");
  std::memcpy(out, rows.data(), bytes);
}

}  // namespace portalsim
