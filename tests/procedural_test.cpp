#include "assets/procedural.h"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/bodies.h"
#include "support.h"

namespace portalsim::procedural {
namespace {

const std::vector<std::string> kShapes = {"gun",   "handle", "rod",   "disk",    "strip",  "plate", "pendant",
                                          "pipe",  "buckle", "tile",  "slab",    "phone",  "knife", "keys",
                                          "coins", "wallet", "watch", "glasses", "bottle", "sheet"};

// Catalogue sizes of the horizontal drawings.
struct Size {
  int w, h;
};
Size catalogue_size(const std::string& s) {
  if (s == "gun") return {44, 30};
  if (s == "handle") return {30, 16};
  if (s == "rod") return {56, 8};
  if (s == "disk") return {30, 30};
  if (s == "strip") return {40, 8};
  if (s == "plate") return {32, 40};
  if (s == "pendant") return {14, 22};
  if (s == "pipe") return {40, 14};
  if (s == "buckle") return {26, 18};
  if (s == "tile") return {28, 28};
  if (s == "slab") return {32, 32};
  if (s == "knife") return {54, 8};
  if (s == "keys") return {20, 13};
  if (s == "coins") return {13, 10};
  if (s == "wallet") return {25, 20};
  if (s == "watch") return {24, 10};
  if (s == "glasses") return {32, 12};
  if (s == "bottle") return {46, 15};
  if (s == "sheet") return {45, 34};
  return {18, 32};  // phone
}

Image sprite_of(const std::string& s, bool vertical, int level = 200) {
  const Size z = catalogue_size(s);
  return vertical ? sprite(s, true, z.h, z.w, level) : sprite(s, false, z.w, z.h, level);
}

int alpha(const Image& im, int x, int y) { return im.at(x, y, 1); }

// Mean of a small square, to keep the tests off single texture pixels.
double mean(const Image& im, int cx, int cy, int r = 2, int c = 0) {
  double sum = 0;
  int n = 0;
  for (int y = std::max(0, cy - r); y <= std::min(im.height - 1, cy + r); ++y)
    for (int x = std::max(0, cx - r); x <= std::min(im.width - 1, cx + r); ++x, ++n) sum += im.at(x, y, c);
  return sum / n;
}

TEST(ProceduralTest, TheDeclaredShapesAreExactlyTheDrawnOnes) {
  ASSERT_EQ(kProceduralShapes.size(), kShapes.size());
  for (const auto& s : kShapes) {
    EXPECT_TRUE(is_procedural_shape(s)) << s;
    EXPECT_NO_THROW(sprite(s, false, 40, 20, 200)) << s;
  }
  for (const char* s : {"", "Gun", "GUN", "sword", "disc", "gun ", "pistol"}) {
    EXPECT_FALSE(is_procedural_shape(s)) << s;
    EXPECT_THROW(sprite(s, false, 40, 20, 200), std::invalid_argument) << s;
  }
}

// The clothing's folds, pinned (no other test pins their bytes): XXH3-64 over every view's
// fold pattern of the built-in subjects and of eight drawn bodies (every pose), in order.
// The folds' sines and the arms' turn are base/plain_math.h's, so the pin holds whatever
// libm the build links. After an intended change to the drawing, put the printed value here.
TEST(ProceduralTest, FoldsArePinned) {
  Catalogue drawn = test::catalogue();
  use_random_bodies(drawn, 11, 8);
  XXH3_state_t* h = XXH3_createState();
  XXH3_64bits_reset(h);
  size_t images = 0;
  for (const AssetSet& a : {test::assets(), build_assets(drawn)})
    for (const auto& subject : a.folds)
      for (const Image& folds : subject) {
        XXH3_64bits_update(h, folds.pixels.data(), folds.pixels.size());
        ++images;
      }
  const unsigned long long got = XXH3_64bits_digest(h);
  XXH3_freeState(h);
  EXPECT_EQ(images, (test::catalogue().subjects.size() + 8) * test::catalogue().sensors.size());
  EXPECT_EQ(got, 0xaf92dd61a4956283ull) << std::hex << "now 0x" << got;
}

TEST(ProceduralTest, SizesAndChannels) {
  Body b;
  for (bool upper : {true, false}) {
    const Image m = mmw_body(b, upper, 200, 150);
    EXPECT_EQ(m.width, 200);
    EXPECT_EQ(m.height, 150);
    EXPECT_EQ(m.channels, 1);
    EXPECT_EQ(m.pixels.size(), 200u * 150u);
  }
  const Image ir = ir_body(b, 100, 200);
  EXPECT_EQ(ir.width, 100);
  EXPECT_EQ(ir.height, 200);
  EXPECT_EQ(ir.channels, 1);
  for (const auto& s : kShapes) {
    const Image h = sprite(s, false, 37, 21, 150);
    EXPECT_EQ(h.width, 37);
    EXPECT_EQ(h.height, 21);
    EXPECT_EQ(h.channels, 2);
    EXPECT_EQ(h.pixels.size(), 37u * 21u * 2u);
    const Image v = sprite(s, true, 21, 37, 150);
    EXPECT_EQ(v.width, 21);
    EXPECT_EQ(v.height, 37);
    EXPECT_EQ(v.channels, 2);
  }
  const Image n = noise_pattern(2, 48);
  EXPECT_EQ(n.width, 48);
  EXPECT_EQ(n.height, 48);
  EXPECT_EQ(n.channels, 1);
}

TEST(ProceduralTest, SpritesHaveCleanOutsideAndSoftEdges) {
  for (const auto& s : kShapes) {
    for (bool v : {false, true}) {
      const Image im = sprite_of(s, v);
      int opaque = 0, clear = 0, partial = 0;
      for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
          const int a = alpha(im, x, y);
          opaque += a == 255;
          clear += a == 0;
          partial += a > 0 && a < 255;
        }
      EXPECT_GT(opaque, 0) << s;
      EXPECT_GT(partial, 0) << s << ": no anti-aliased edge";
      // Boxy shapes fill their box up to slightly rounded corners.
      if (s != "tile" && s != "plate" && s != "rod" && s != "strip" && s != "pipe" && s != "wallet" && s != "sheet") {
        EXPECT_GT(clear, 0) << s;
      }
    }
  }
}

TEST(ProceduralTest, CornersAndHolesAreTransparent) {
  for (const char* s : {"disk", "pendant", "gun"}) {
    for (bool v : {false, true}) {
      const Image im = sprite_of(s, v);
      const int w = im.width - 1, h = im.height - 1;
      EXPECT_EQ(alpha(im, 0, 0), 0) << s << " v=" << v;
      EXPECT_EQ(alpha(im, w, 0), 0) << s << " v=" << v;
      EXPECT_EQ(alpha(im, 0, h), 0) << s << " v=" << v;
      EXPECT_EQ(alpha(im, w, h), 0) << s << " v=" << v;
    }
  }
  const Image disk = sprite("disk", false, 30, 30, 185);
  EXPECT_EQ(alpha(disk, 14, 14), 0);
  EXPECT_EQ(alpha(disk, 15, 15), 0);
  EXPECT_EQ(alpha(disk, 15, 5), 255);  // the data area around the hole
  const Image buckle = sprite("buckle", false, 26, 18, 226);
  EXPECT_EQ(alpha(buckle, 13, 6), 0);  // the buckle's opening, above the prong
}

TEST(ProceduralTest, CentresAreOpaque) {
  for (const char* s : {"plate", "tile", "phone", "slab", "pipe", "rod"}) {
    for (bool v : {false, true}) {
      const Image im = sprite_of(s, v);
      EXPECT_EQ(alpha(im, im.width / 2, im.height / 2), 255) << s << " v=" << v;
    }
  }
}

TEST(ProceduralTest, VerticalIsTheHorizontalTurnedClockwise) {
  for (const auto& s : kShapes) {
    const Image h = sprite_of(s, false), v = sprite_of(s, true);
    ASSERT_EQ(v.width, h.height);
    ASSERT_EQ(v.height, h.width);
    for (int y = 0; y < v.height; ++y)
      for (int x = 0; x < v.width; ++x)
        for (int c = 0; c < 2; ++c) ASSERT_EQ(v.at(x, y, c), h.at(y, h.height - 1 - x, c)) << s << " " << x << "," << y;
  }
}

TEST(ProceduralTest, VerticalRodStandsUpright) {
  // The rod fills its 8x56 box: alpha sits in the central columns over the whole height,
  // with soft rounded ends and a soft edge on the outer columns.
  const Image rod = sprite("rod", true, 8, 56, 232);
  long band = 0, total = 0;
  for (int y = 0; y < rod.height; ++y) {
    int row = 0;
    for (int x = 0; x < rod.width; ++x) {
      row += alpha(rod, x, y);
      if (x >= 1 && x <= 6) band += alpha(rod, x, y);
    }
    EXPECT_GT(row, 0) << y;
    total += row;
  }
  EXPECT_GE(band, total * 8 / 10);
  for (int y = 4; y < 52; ++y) EXPECT_EQ(alpha(rod, 4, y), 255) << y;
  EXPECT_LT(alpha(rod, 0, 0), 128);
  EXPECT_LT(alpha(rod, 7, 55), 128);
  // Horizontal: the same along a row band.
  const Image flat = sprite("rod", false, 56, 8, 232);
  for (int x = 4; x < 52; ++x) EXPECT_EQ(alpha(flat, x, 4), 255) << x;
  EXPECT_LT(alpha(flat, 0, 0), 128);
}

TEST(ProceduralTest, GunBarrelPointsRightThenDown) {
  const Image h = sprite("gun", false, 44, 30, 238);
  // Horizontal: the muzzle reaches the right edge near the top; the grip reaches the bottom
  // on the left, and the bottom right (under the barrel) is empty.
  int right_top = 0, right_bottom = 0;
  for (int y = 0; y < 15; ++y) right_top += alpha(h, 43, y);
  for (int y = 15; y < 30; ++y) right_bottom += alpha(h, 43, y);
  EXPECT_GT(right_top, 0);
  EXPECT_EQ(right_bottom, 0);
  EXPECT_GT(alpha(h, 6, 28), 0);
  EXPECT_EQ(alpha(h, 38, 26), 0);
  // Vertical: the muzzle is at the bottom.
  const Image v = sprite("gun", true, 30, 44, 238);
  int bottom = 0;
  for (int x = 0; x < v.width; ++x) bottom += alpha(v, x, v.height - 1);
  EXPECT_GT(bottom, 0);
}

TEST(ProceduralTest, SpriteValuesStayNearTheLevel) {
  for (const auto& s : kShapes) {
    for (int level : {40, 128, 238}) {
      const Image im = sprite_of(s, false, level);
      double sum = 0;
      int n = 0;
      for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
          if (alpha(im, x, y) == 0) continue;
          const int v = im.at(x, y, 0);
          EXPECT_LE(std::abs(v - level), 41) << s << " level " << level;
          sum += v;
          ++n;
        }
      EXPECT_NEAR(sum / n, level, 20.0) << s << " level " << level;
    }
    // Extreme levels clamp rather than wrap.
    const Image lo = sprite_of(s, false, -50), hi = sprite_of(s, false, 400);
    for (size_t i = 0; i < lo.pixels.size(); i += 2) EXPECT_LE(lo.pixels[i], 40) << s;
    for (size_t i = 0; i < hi.pixels.size(); i += 2) EXPECT_GE(hi.pixels[i], 215) << s;
  }
}

TEST(ProceduralTest, SpritesHaveShadingDetail) {
  for (const auto& s : kShapes) {
    const Image im = sprite_of(s, false, 128);
    int lo = 255, hi = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x)
        if (alpha(im, x, y) == 255) {
          lo = std::min<int>(lo, im.at(x, y, 0));
          hi = std::max<int>(hi, im.at(x, y, 0));
        }
    EXPECT_GE(hi - lo, 10) << s << " looks flat";
  }
}

TEST(ProceduralTest, MmwBodyIsBrighterThanBackground) {
  Body b;
  const Image up = mmw_body(b, true, 200, 200), lo = mmw_body(b, false, 200, 200);
  // Torso and hips near the material level, corners near the background level.
  EXPECT_NEAR(mean(up, 100, 100), b.mmw_level, 20);
  EXPECT_NEAR(mean(lo, 100, 30), b.mmw_level, 20);
  for (const Image* im : {&up, &lo}) {
    EXPECT_NEAR(mean(*im, 2, 2), b.mmw_background, 8);
    EXPECT_NEAR(mean(*im, 197, 2), b.mmw_background, 8);
    EXPECT_NEAR(mean(*im, 2, 197), b.mmw_background, 8);
    EXPECT_NEAR(mean(*im, 197, 197), b.mmw_background, 8);
  }
  // Upper: neck at the top centre, arms at the sides with a gap to the torso below the
  // armpits, shoulders wider than the neck.
  EXPECT_GT(mean(up, 100, 6, 1), 100);
  EXPECT_LT(mean(up, 70, 4, 1), 60);
  EXPECT_GT(mean(up, 35, 100, 1), 100);
  EXPECT_GT(mean(up, 165, 100, 1), 100);
  EXPECT_LT(mean(up, 48, 130, 0), 100);
  EXPECT_LT(mean(up, 152, 130, 0), 100);
  EXPECT_GT(mean(up, 35, 30, 1), 100);
  // Lower: two legs with a gap between them, background outside the feet.
  EXPECT_GT(mean(lo, 73, 100, 1), 100);
  EXPECT_GT(mean(lo, 126, 100, 1), 100);
  EXPECT_LT(mean(lo, 100, 150, 1), 60);
  EXPECT_LT(mean(lo, 30, 190, 1), 60);
  auto any_body = [&](int y, int x0, int x1) {
    for (int x = x0; x <= x1; ++x)
      if (lo.at(x, y) > 100) return true;
    return false;
  };
  EXPECT_TRUE(any_body(193, 54, 94));    // right foot, under the right-ankle region
  EXPECT_TRUE(any_body(193, 106, 146));  // left foot
  EXPECT_FALSE(any_body(199, 0, 199));
  // Shading: brighter inside than at the outline.
  EXPECT_GT(mean(up, 100, 120), mean(up, 56, 120, 0) + 5);
}

TEST(ProceduralTest, BuildWidensAndSubjectVaries) {
  auto body_width = [](const Image& im, int y) {
    int n = 0;
    for (int x = 0; x < im.width; ++x) n += im.at(x, y) > 90;
    return n;
  };
  Body thin, wide;
  thin.shape.build = 0.85;
  wide.shape.build = 1.15;
  EXPECT_GT(body_width(mmw_body(wide, true, 200, 200), 120), body_width(mmw_body(thin, true, 200, 200), 120) + 10);
  EXPECT_GT(body_width(mmw_body(wide, false, 200, 200), 60), body_width(mmw_body(thin, false, 200, 200), 60) + 10);
  Body s0, s1;
  s1.subject = 1;
  EXPECT_NE(mmw_body(s0, true, 200, 200).pixels, mmw_body(s1, true, 200, 200).pixels);
  Body dim;
  dim.mmw_level = 120;
  EXPECT_NEAR(mean(mmw_body(dim, true, 200, 200), 100, 100), 120, 20);
}

TEST(ProceduralTest, IrTorsoIsWarmestAndExtremitiesCooler) {
  Body b;
  const Image ir = ir_body(b, 100, 200);
  const double torso = mean(ir, 50, 60);
  EXPECT_NEAR(torso, b.ir_core, 15);
  EXPECT_NEAR(mean(ir, 2, 2), b.ir_background, 8);
  EXPECT_NEAR(mean(ir, 97, 197), b.ir_background, 8);
  // The ankles (IR row 190) and hands (row 92) are cooler than the torso, but still warm.
  auto row_max = [&](int y, int x0, int x1) {
    int m = 0;
    for (int x = x0; x <= x1; ++x) m = std::max<int>(m, ir.at(x, y));
    return m;
  };
  EXPECT_LT(row_max(190, 0, 99), torso - 20);
  EXPECT_GT(row_max(190, 0, 99), b.ir_background + 60);
  EXPECT_LT(row_max(92, 0, 20), torso - 20);
  EXPECT_GT(row_max(92, 0, 20), b.ir_background + 60);
  // Knees (row 155) sit between.
  EXPECT_LT(row_max(155, 0, 49), torso);
  EXPECT_GT(row_max(155, 0, 49), row_max(190, 0, 49));
}

TEST(ProceduralTest, IrSilhouetteMatchesMmwAtHalfScale) {
  Body b;
  b.subject = 2;
  b.shape.build = 1.1;
  const Image ir = ir_body(b, 100, 200);
  const Image up = mmw_body(b, true, 200, 200), lo = mmw_body(b, false, 200, 200);
  const int ir_mid = (b.ir_core + b.ir_background) / 2 - 20;
  const int mmw_mid = (b.mmw_level + b.mmw_background) / 2;
  int agree = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 100; ++x) {
      const Image& m = y < 100 ? up : lo;
      const int my = 2 * (y % 100);
      // Average the 2x2 MMW block this IR pixel covers.
      const int mv = (m.at(2 * x, my) + m.at(2 * x + 1, my) + m.at(2 * x, my + 1) + m.at(2 * x + 1, my + 1)) / 4;
      agree += (ir.at(x, y) > ir_mid) == (mv > mmw_mid);
    }
  EXPECT_GT(agree, 100 * 200 * 97 / 100);
}

TEST(ProceduralTest, NoisePatternsAreLocalAndDistinct) {
  for (int size : {64, 17, 3}) {
    for (int k = 0; k < kProceduralNoisePatterns; ++k) {
      const Image n = noise_pattern(k, size);
      for (int i = 0; i < size; ++i) {
        EXPECT_EQ(n.at(i, 0), 128) << k;
        EXPECT_EQ(n.at(i, size - 1), 128) << k;
        EXPECT_EQ(n.at(0, i), 128) << k;
        EXPECT_EQ(n.at(size - 1, i), 128) << k;
      }
      int dev = 0;
      for (uint8_t p : n.pixels) dev = std::max(dev, std::abs(p - 128));
      EXPECT_LE(dev, 46) << k;
      if (size == 64) {
        EXPECT_GE(dev, 25) << k;
      }
    }
  }
  std::vector<Image> all;
  for (int k = 0; k < kProceduralNoisePatterns; ++k) all.push_back(noise_pattern(k, 64));
  for (int a = 0; a < kProceduralNoisePatterns; ++a)
    for (int b = a + 1; b < kProceduralNoisePatterns; ++b) {
      long diff = 0;
      for (size_t i = 0; i < all[a].pixels.size(); ++i) diff += std::abs(all[a].pixels[i] - all[b].pixels[i]);
      EXPECT_GT(diff / static_cast<double>(all[a].pixels.size()), 4.0) << a << " vs " << b;
    }
}

// Mean absolute difference between neighbours along x and along y, over the tile's middle.
void roughness(const Image& n, double& along_x, double& along_y) {
  long dx = 0, dy = 0, count = 0;
  for (int y = 16; y < 48; ++y)
    for (int x = 16; x < 48; ++x, ++count) {
      dx += std::abs(n.at(x + 1, y) - n.at(x, y));
      dy += std::abs(n.at(x, y + 1) - n.at(x, y));
    }
  along_x = static_cast<double>(dx) / count;
  along_y = static_cast<double>(dy) / count;
}

TEST(ProceduralTest, NoisePatternsHaveTheirCharacter) {
  double sx, sy, hx, hy, bx, by, vx, vy;
  roughness(noise_pattern(0, 64), sx, sy);
  roughness(noise_pattern(1, 64), hx, hy);
  roughness(noise_pattern(2, 64), bx, by);
  roughness(noise_pattern(4, 64), vx, vy);
  EXPECT_GT(hy, 1.5 * hx);  // streaks change across rows, not along them
  EXPECT_GT(vx, 1.5 * vy);  // bands change across columns
  EXPECT_GT(sx, 2.0 * bx);  // speckle is fine, blotches are smooth
  EXPECT_GT(sy, 2.0 * by);
  // Rings: the centre and a point half a ring period out differ strongly.
  const Image r = noise_pattern(3, 64);
  int lo = 255, hi = 0;
  for (int x = 31; x < 48; ++x) {
    lo = std::min<int>(lo, r.at(x, 31));
    hi = std::max<int>(hi, r.at(x, 31));
  }
  EXPECT_GT(hi - lo, 50);
}

TEST(ProceduralTest, IronPaletteRunsBlackToWhite) {
  const auto p = ir_palette();
  auto luma = [&](int i) { return 0.299 * p[i][0] + 0.587 * p[i][1] + 0.114 * p[i][2]; };
  EXPECT_EQ(p[0][0], 0);
  EXPECT_EQ(p[0][1], 0);
  EXPECT_EQ(p[0][2], 0);
  EXPECT_GT(luma(255), 230);
  for (int i = 1; i < 256; ++i) EXPECT_GE(luma(i), luma(i - 1) - 2.0) << i;
  EXPECT_GT(luma(255) - luma(0), 220);
  // Blue early, magenta, then red, orange and yellow.
  EXPECT_GT(p[40][2], p[40][0]);
  EXPECT_GT(p[40][2], p[40][1]);
  EXPECT_GT(p[110][0], 100);
  EXPECT_GT(p[110][2], 100);
  EXPECT_LT(p[110][1], 40);
  EXPECT_GT(p[155][0], 180);
  EXPECT_GT(p[155][0], 2 * p[155][2]);
  EXPECT_GT(p[190][0], 200);
  EXPECT_GT(p[190][1], 80);
  EXPECT_LT(p[190][2], 40);
  EXPECT_GT(p[225][1], 180);
}

TEST(ProceduralTest, InvalidArgumentsThrow) {
  Body b;
  EXPECT_THROW(mmw_body(b, true, 0, 200), std::invalid_argument);
  EXPECT_THROW(mmw_body(b, false, 200, -1), std::invalid_argument);
  EXPECT_THROW(ir_body(b, 100, 0), std::invalid_argument);
  EXPECT_THROW(sprite("gun", false, 0, 10, 100), std::invalid_argument);
  EXPECT_THROW(sprite("gun", true, 10, -3, 100), std::invalid_argument);
  EXPECT_THROW(sprite("sword", false, 10, 10, 100), std::invalid_argument);
  EXPECT_THROW(sprite("", false, 10, 10, 100), std::invalid_argument);
  EXPECT_THROW(noise_pattern(-1, 64), std::invalid_argument);
  EXPECT_THROW(noise_pattern(kProceduralNoisePatterns, 64), std::invalid_argument);
  EXPECT_THROW(noise_pattern(0, 0), std::invalid_argument);
}

TEST(ProceduralTest, TinySizesWork) {
  Body b;
  for (bool upper : {true, false}) {
    const Image m = mmw_body(b, upper, 1, 1);
    EXPECT_EQ(m.pixels.size(), 1u);
    EXPECT_GT(mmw_body(b, upper, 2, 3).pixels.size(), 0u);
  }
  EXPECT_EQ(ir_body(b, 1, 1).pixels.size(), 1u);
  for (const auto& s : kShapes) {
    for (bool v : {false, true}) {
      for (int w : {1, 2, 3})
        for (int h : {1, 2, 5}) {
          const Image im = sprite(s, v, w, h, 200);
          ASSERT_EQ(im.pixels.size(), static_cast<size_t>(w) * h * 2) << s;
          for (size_t i = 0; i < im.pixels.size(); i += 2) EXPECT_LE(std::abs(im.pixels[i] - 200), 41) << s;
        }
    }
  }
  for (int k = 0; k < kProceduralNoisePatterns; ++k) {
    EXPECT_EQ(noise_pattern(k, 1).pixels, std::vector<uint8_t>{128});
    EXPECT_EQ(noise_pattern(k, 2).pixels, std::vector<uint8_t>(4, 128));
  }
}

TEST(ProceduralTest, LargeAndOddSizesWork) {
  Body b;
  const Image big = mmw_body(b, true, 4096, 4096);
  ASSERT_EQ(big.pixels.size(), 4096u * 4096u);
  EXPECT_NEAR(mean(big, 2048, 2048), b.mmw_level, 20);
  EXPECT_NEAR(mean(big, 3, 3), b.mmw_background, 8);
  // Non-square views keep the proportions: the torso centre is still body.
  const Image wide = mmw_body(b, false, 640, 120);
  EXPECT_NEAR(mean(wide, 320, 15), b.mmw_level, 20);
  const Image ir = ir_body(b, 333, 517);
  EXPECT_GT(mean(ir, 166, 150), b.ir_core - 20);
  const Image huge_sprite = sprite("gun", true, 600, 900, 238);
  EXPECT_EQ(alpha(huge_sprite, 0, 0), 0);
  EXPECT_EQ(noise_pattern(3, 1024).pixels.size(), 1024u * 1024u);
}

}  // namespace
}  // namespace portalsim::procedural
