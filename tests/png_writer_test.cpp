// The PNG writer of image folders (host/assets/png_writer.h): its files read back to the
// same pixels through OpenImageIO and through Python's PIL (an independent decoder that
// checks every chunk's CRC and the zlib stream's Adler-32), at every level, for every
// channel count, and its bytes depend only on the pixels and the level.
#include "assets/png_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "assets/image_io.h"
#include "base/error.h"
#include "run_binary.h"
#include "scene/philox.h"

namespace {

namespace fs = std::filesystem;
using portalsim::Image;

// Noise (nothing to compress), a smooth ramp and flat runs (much to compress), side by side.
Image test_image(int w, int h, int c, uint64_t seed) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) {
        uint8_t v;
        if (x < w / 3)
          v = static_cast<uint8_t>(portalsim::draw(seed, static_cast<uint64_t>(y) * w + x, 7, k)[0]);
        else if (x < 2 * w / 3)
          v = static_cast<uint8_t>(x + 2 * y + 40 * k);
        else
          v = y < h / 2 ? 0 : 200;
        img.at(x, y, k) = v;
      }
  return img;
}

struct Case {
  int w, h, c;
};
// 1x1; a width not a multiple of anything; 300x300x3 (270 kB): several stored blocks at level 0.
const std::vector<Case> kCases{{1, 1, 1}, {37, 5, 2}, {200, 200, 1}, {100, 200, 3}, {23, 41, 4}, {300, 300, 3}};

std::string name_of(const Case& k, int level) {
  return std::to_string(k.w) + "x" + std::to_string(k.h) + "x" + std::to_string(k.c) + "-level" + std::to_string(level);
}

TEST(PngWriter, OpenImageIOReadsBackTheSamePixelsAtEveryLevel) {
  portalsim::test::TempDir t;
  for (const Case& k : kCases)
    for (int level = 0; level <= portalsim::kMaxPngLevel; ++level) {
      SCOPED_TRACE(name_of(k, level));
      Image img = test_image(k.w, k.h, k.c, 3);
      // OpenImageIO's reader multiplies colour by alpha (its default for PNG): an opaque
      // alpha keeps the colour as written. PIL's test below checks any alpha exactly.
      if (k.c == 2 || k.c == 4)
        for (size_t p = static_cast<size_t>(k.c) - 1; p < img.pixels.size(); p += static_cast<size_t>(k.c))
          img.pixels[p] = 255;
      const std::string path = (t.w() / (name_of(k, level) + ".png")).string();
      portalsim::write_image(path, img, level);
      const Image back = portalsim::read_image(path, "test");
      EXPECT_EQ(back.width, k.w);
      EXPECT_EQ(back.height, k.h);
      EXPECT_EQ(back.channels, k.c);
      EXPECT_TRUE(back.pixels == img.pixels);
    }
}

TEST(PngWriter, PilReadsBackTheSamePixelsAtEveryLevel) {
  portalsim::test::TempDir t;
  int files = 0;
  for (const Case& k : kCases)
    for (int level = 0; level <= portalsim::kMaxPngLevel; ++level) {
      const Image img = test_image(k.w, k.h, k.c, 5);
      const std::string stem = (t.w() / name_of(k, level)).string();
      portalsim::write_image(stem + ".png", img, level);
      portalsim::test::spit(stem + ".raw", std::string(img.pixels.begin(), img.pixels.end()));
      ++files;
    }
  // verify() checks the chunks' CRCs; a second open decodes (zlib checks the Adler-32).
  const std::string script =
      "import sys, glob\n"
      "from PIL import Image\n"
      "n = 0\n"
      "for p in sorted(glob.glob(sys.argv[1] + '/*.png')):\n"
      "    Image.open(p).verify()\n"
      "    im = Image.open(p)\n"
      "    im.load()\n"
      "    want = open(p[:-4] + '.raw', 'rb').read()\n"
      "    if im.tobytes() != want: sys.exit(p + ': pixels differ')\n"
      "    n += 1\n"
      "print('read', n)\n";
  portalsim::test::spit(t.w() / "check.py", script);
  const portalsim::test::Result r = portalsim::test::finish(
      portalsim::test::start_program(t.cap(), "/usr/bin/python3", {(t.w() / "check.py").string(), t.w().string()}));
  EXPECT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
  EXPECT_EQ(r.out, "read " + std::to_string(files) + "\n") << portalsim::test::describe(r);
}

TEST(PngWriter, LevelZeroStoresAndLevelOneCompresses) {
  const Image img = test_image(200, 200, 1, 9);
  std::string stored, fast;
  portalsim::encode_png(img.pixels.data(), 200, 200, 1, 0, stored);
  portalsim::encode_png(img.pixels.data(), 200, 200, 1, 1, fast);
  // Level 0: every row and its filter byte, plus the chunks' and deflate blocks' framing.
  EXPECT_GE(stored.size(), img.pixels.size() + 200);
  EXPECT_LT(stored.size(), img.pixels.size() + 200 + 100);
  // Two thirds of the image are a ramp and flat runs.
  EXPECT_LT(fast.size(), stored.size() * 2 / 3);
}

TEST(PngWriter, BytesDependOnlyOnThePixelsAndTheLevel) {
  const Image img = test_image(100, 200, 3, 11);
  std::vector<std::vector<std::string>> out(4);
  std::vector<std::thread> threads;
  // Each thread keeps its own scratch buffers: bytes from other threads and repeated calls agree.
  for (size_t t = 0; t < out.size(); ++t)
    threads.emplace_back([&, t] {
      for (int level = 0; level <= portalsim::kMaxPngLevel; ++level) {
        std::string s;
        portalsim::encode_png(img.pixels.data(), 100, 200, 3, level, s);
        out[t].push_back(s);
      }
    });
  for (std::thread& th : threads) th.join();
  for (size_t t = 1; t < out.size(); ++t) EXPECT_TRUE(out[t] == out[0]) << "thread " << t;
  EXPECT_NE(out[0][1], out[0][2]) << "levels 1 and 2 are different encodings";
}

TEST(PngWriter, UnwritablePathIsAnOutputErrorNamingIt) {
  portalsim::test::TempDir t;
  const std::string path = (t.w() / "missing" / "a.png").string();
  const Image img = test_image(4, 4, 1, 1);
  try {
    portalsim::write_image(path, img);
    FAIL() << "no error";
  } catch (const portalsim::OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace
