// Image files read through OpenImageIO (host/assets/oiio/codec.cpp): an 8-bit file's samples
// byte for byte, a 16-bit file's converted as OpenImageIO converts them, in 1 and 3 channels, and
// samples of another type refused naming the file.
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

TEST(ImageRead, EightBitSamplesAreReadByteForByte) {
  portalsim::test::TempDir t;
  for (const int channels : {1, 3}) {
    const int w = 97, h = 13;
    std::vector<uint32_t> v(static_cast<size_t>(w) * h * channels);
    std::mt19937 rng(11);
    for (uint32_t& x : v) x = rng() & 0xff;
    const fs::path f = t.w() / ("eight" + std::to_string(channels) + (channels == 1 ? ".pgm" : ".ppm"));
    portalsim::test::spit(f, netpbm(w, h, channels, 255, v));
    const Image img = portalsim::read_image(f.string(), "test");
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    ASSERT_EQ(img.channels, channels);
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
    const fs::path f = t.w() / ("sixteen" + std::to_string(channels) + (channels == 1 ? ".pgm" : ".ppm"));
    portalsim::test::spit(f, netpbm(w, h, channels, 65535, v));
    const Image img = portalsim::read_image(f.string(), "test");
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    ASSERT_EQ(img.channels, channels);
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
