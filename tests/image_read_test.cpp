// Image files read through OpenImageIO (host/assets/oiio/codec.cpp): an 8-bit file's samples
// byte for byte, a 16-bit file's converted as OpenImageIO converts them, in 1 and 3 channels,
// from rows (netpbm) and from tiles (a tiled TIFF), and samples of another type refused
// naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "assets/image_io.h"
#include "base/error.h"
#include "run_binary.h"

namespace {

namespace fs = std::filesystem;
using portalsim::Image;

// A binary PGM (1 channel) or PPM (3): header, then the samples big-endian, as netpbm has it.
std::string netpbm(int w, int h, int channels, int maxval, const std::vector<uint32_t>& samples) {
  std::string s = std::string(channels == 1 ? "P5" : "P6") + "\n" + std::to_string(w) + " " + std::to_string(h) + "\n" +
                  std::to_string(maxval) + "\n";
  for (const uint32_t v : samples) {
    if (maxval > 255) s.push_back(static_cast<char>(v >> 8));
    s.push_back(static_cast<char>(v & 0xff));
  }
  return s;
}

// The samples written as a netpbm file, and by oiiotool as a TIFF of 64x64 tiles of the same
// type; each read back. Empty where a file could not be made or read as w x h x channels.
std::vector<Image> read_rows_and_tiles(const portalsim::test::TempDir& t, const std::string& name, int w, int h,
                                       int channels, int maxval, const std::vector<uint32_t>& samples) {
  const fs::path rows = t.w() / (name + (channels == 1 ? ".pgm" : ".ppm")), tiles = t.w() / (name + "-tiled.tif");
  portalsim::test::spit(rows, netpbm(w, h, channels, maxval, samples));
  const portalsim::test::Result r = portalsim::test::finish(portalsim::test::start_program(
      t.cap(), "/usr/bin/oiiotool",
      {rows.string(), "-d", maxval > 255 ? "uint16" : "uint8", "--tile", "64", "64", "-o", tiles.string()}));
  if (!(r.exited && r.status == 0)) {
    ADD_FAILURE() << portalsim::test::describe(r);
    return {};
  }
  std::vector<Image> read;
  for (const fs::path& f : {rows, tiles}) {
    read.push_back(portalsim::read_image(f.string(), "test"));
    const Image& img = read.back();
    if (img.width != w || img.height != h || img.channels != channels) {
      ADD_FAILURE() << f << " read as " << img.width << "x" << img.height << "x" << img.channels;
      return {};
    }
  }
  return read;
}

TEST(ImageRead, EightBitSamplesAreReadByteForByte) {
  portalsim::test::TempDir t;
  for (const int channels : {1, 3}) {
    const int w = 97, h = 13;
    std::vector<uint32_t> v(static_cast<size_t>(w) * h * channels);
    std::mt19937 rng(11);
    for (uint32_t& x : v) x = rng() & 0xff;
    const std::vector<Image> read = read_rows_and_tiles(t, "eight" + std::to_string(channels), w, h, channels, 255, v);
    ASSERT_EQ(read.size(), 2u);
    for (const Image& img : read)
      for (size_t i = 0; i < v.size(); ++i) ASSERT_EQ(img.pixels[i], v[i]) << "sample " << i;
  }
}

// A 16-bit sample v reads as OpenImageIO converts it, (255 v + 32768) >> 16 (v 255 / 65536,
// rounded; within one level of v / 257, 65535 at 255). Every 16-bit value, then back down,
// in each channel count.
TEST(ImageRead, SixteenBitSamplesReadAsOpenImageIOConvertsThem) {
  portalsim::test::TempDir t;
  for (const int channels : {1, 3}) {
    const int w = 256, h = 65536 / (w * channels) + 2;
    std::vector<uint32_t> v(static_cast<size_t>(w) * h * channels);
    for (size_t i = 0; i < v.size(); ++i) v[i] = i < 65536 ? static_cast<uint32_t>(i) : 65535 - (i % 65536);
    const std::vector<Image> read =
        read_rows_and_tiles(t, "sixteen" + std::to_string(channels), w, h, channels, 65535, v);
    ASSERT_EQ(read.size(), 2u);
    for (const Image& img : read)
      for (size_t i = 0; i < v.size(); ++i) {
        ASSERT_EQ(img.pixels[i], (255 * v[i] + 32768) >> 16) << "sample " << i << ": " << v[i];
        ASSERT_LE(std::abs(img.pixels[i] - v[i] / 257.0), 0.5 + 1.0 / 256) << "sample " << i << ": " << v[i];
      }
  }
}

// A float image (PFM) has no 8-bit levels to read: refused, naming the file and its type.
TEST(ImageRead, FloatSamplesAreRefusedNamingTheFile) {
  portalsim::test::TempDir t;
  const fs::path f = t.w() / "float.pfm";
  std::string s = "Pf\n2 2\n-1.0\n";
  const float px[4] = {0.0f, 0.25f, 0.5f, 1.0f};
  s.append(reinterpret_cast<const char*>(px), sizeof px);
  portalsim::test::spit(f, s);
  try {
    (void)portalsim::read_image(f.string(), "test");
    ADD_FAILURE() << "a float image was read";
  } catch (const portalsim::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(f.string()), std::string::npos) << m;
    EXPECT_NE(m.find("image samples are float; expected 8- or 16-bit integers"), std::string::npos) << m;
  }
}

}  // namespace
