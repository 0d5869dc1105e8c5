// data.h5 through libhdf5, and read back (a merge reads its parts' datasets and
// attributes). Datasets are chunked 64 rows along N. Uncompressed, the file is laid out
// first (attributes, and every chunk allocated, chunk 0 of each dataset, then chunk 1 of
// each, and so on, so that rows written in order fill the file nearly in order) and
// closed, then rows are written in place at their chunks' addresses: HDF5's metadata is
// final before any row is, so a kill -9 mid-run leaves a valid file to resume into.
// Compressed, it is built through HDF5 from per-tensor .npy files at the end. One layout,
// so the bytes of data.h5 depend only on its contents and their order.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace portalsim {

enum class TensorType { u8, i16, f32, f64 };
size_t type_size(TensorType t);
const char* npy_descr(TensorType t);  // "|u1", "<i2", "<f4", "<f8"

// A dataset: name, element type, per-row shape (after N) and, for features, column names.
struct H5Dataset {
  std::string name;
  TensorType type = TensorType::u8;
  std::vector<uint64_t> dims;
  std::vector<std::string> columns;  // the dataset's "columns" attribute; none when empty
  size_t row_bytes() const;
};

// A root attribute of UTF-8 strings: one (scalar) or a 1-d array.
struct H5Attribute {
  std::string name;
  std::vector<std::string> values;
  bool scalar = true;
};

// Rows per chunk along N (fewer when the file has fewer rows).
constexpr uint64_t kH5ChunkRows = 64;

struct H5Layout {
  uint64_t rows = 0;
  bool compress = false;                // shuffle + gzip 4
  std::vector<H5Attribute> attributes;  // written in name order, with "datasets" (their names, in order)
  std::vector<H5Dataset> datasets;      // in the order written
};

// Writes dir/data.h5 (to data.h5.tmp, synced, then renamed). `npy_path(i)` is the .npy
// file holding dataset i's rows; its header is skipped. Throws OutputError.
// (Uncompressed: create_h5_in_place, then the rows written at their offsets.)
void write_h5(const std::string& dir, const H5Layout& layout, const std::vector<std::string>& npy_paths);

// Where an uncompressed data.h5's rows go: row r of dataset k is at
// address[k][r / chunk_rows] + (r % chunk_rows) * row_bytes. The chunks lie in the file in
// the order chunk 0 of every dataset, chunk 1 of every dataset, ...; the last chunk's rows
// past the end are never written (zeros).
struct H5InPlace {
  uint64_t chunk_rows = 1;
  std::vector<std::vector<uint64_t>> address;  // [dataset][chunk]
  uint64_t file_size = 0;
  uint64_t at(size_t k, uint64_t row, size_t row_bytes) const {
    return address[k][row / chunk_rows] + (row % chunk_rows) * row_bytes;
  }
};

// Creates `path` laid out for `layout` (not compressed), closes it and says where its rows
// go; they are then written there with write_at. Throws OutputError.
H5InPlace create_h5_in_place(const std::string& path, const H5Layout& layout);
// The same of a file create_h5_in_place made (resuming a run): checks its datasets are
// `layout`'s, lays the layout out again in `scratch` (removed after) and checks that every
// byte of the file outside the chunks, and its size, are the same. Throws OutputError
// naming the file.
H5InPlace h5_in_place_layout(const std::string& path, const H5Layout& layout, const std::string& scratch);
// pwrite all of [data, data + n) at `offset`. Throws OutputError naming `path`.
void write_at(int fd, const char* data, size_t n, uint64_t offset, const std::string& path);
// pread all of [data, data + n) from `offset`. Throws OutputError naming `path` and `what`
// the bytes were read for ("for resume").
void read_at(int fd, char* data, size_t n, uint64_t offset, const std::string& path, const char* what);

// The layout of a data.h5 this program wrote. Throws InputError naming the file.
H5Layout read_h5_layout(const std::string& path);

// Reads rows [first, first + n) of a dataset into `out` (n * row_bytes bytes).
void read_h5_rows(const std::string& path, const H5Dataset& ds, uint64_t first, uint64_t n, char* out);

}  // namespace portalsim
