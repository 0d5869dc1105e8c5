// create_h5_in_place's chunk addresses against HDF5's own chunk index, over enough chunks
// that HDF5 splits its index nodes (the chunks whose address create_h5_in_place infers and
// checks after the file is closed), and in the order the writer relies on.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <string>
#include <vector>

#include "run_binary.h"
#include "sink/h5_file.h"

namespace {

using portalsim::H5Dataset;
using portalsim::H5InPlace;
using portalsim::H5Layout;
using portalsim::TensorType;

uint64_t hdf5_chunk_address(hid_t file, const H5Dataset& d, uint64_t row) {
  const hid_t ds = H5Dopen2(file, d.name.c_str(), H5P_DEFAULT);
  std::vector<hsize_t> origin(d.dims.size() + 1, 0);
  origin[0] = row;
  unsigned filters = 0;
  haddr_t addr = HADDR_UNDEF;
  hsize_t size = 0;
  EXPECT_GE(H5Dget_chunk_info_by_coord(ds, origin.data(), &filters, &addr, &size), 0);
  H5Dclose(ds);
  return addr;
}

TEST(H5Layout, ChunkAddressesAreHdf5sInFileOrder) {
  portalsim::test::TempDir t;
  H5Layout layout;
  layout.rows = 1500 * portalsim::kH5ChunkRows + 17;  // index nodes of 1,024 chunks split
  layout.attributes.push_back({"portalsim", {"test"}, true});
  H5Dataset a, b, c;
  a.name = "label";
  b.name = "region_object";
  b.type = TensorType::i16;
  b.dims = {13};
  c.name = "features";
  c.type = TensorType::f32;
  c.dims = {5};
  layout.datasets = {a, b, c};
  const std::string path = (t.w() / "l.h5").string();
  const H5InPlace place = portalsim::create_h5_in_place(path, layout);
  ASSERT_EQ(place.chunk_rows, portalsim::kH5ChunkRows);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  uint64_t end = 0, differ = 0;
  for (uint64_t ch = 0; ch < place.address[0].size(); ++ch)
    for (size_t k = 0; k < layout.datasets.size(); ++k) {
      const uint64_t at = place.address[k][ch];
      differ += at != hdf5_chunk_address(file, layout.datasets[k], ch * place.chunk_rows);
      EXPECT_GE(at, end) << "chunk " << ch << " of " << layout.datasets[k].name << " out of file order";
      end = at + place.chunk_rows * layout.datasets[k].row_bytes();
    }
  H5Fclose(file);
  EXPECT_EQ(place.address[0].size(), 1501u);
  EXPECT_EQ(differ, 0u) << "chunk addresses that are not where HDF5's index puts them";
  EXPECT_LE(end, place.file_size);
  // Laid out again for a resume: the same addresses, the file compared outside the chunks.
  const H5InPlace again = portalsim::h5_in_place_layout(path, layout, (t.w() / "scratch.h5").string());
  EXPECT_EQ(again.address, place.address);
}

}  // namespace
