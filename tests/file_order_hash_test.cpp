// FileOrderHash against XXH3-64 of the finished file: pieces fed in any order across
// extents give the hash of the file in address order, bytes between extents read from the
// file, unfilled tails as zeros; a resumed hash (skip_to, held pieces fed again) goes on
// to the same digest.
#include "sink/file_order_hash.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"
#include "run_binary.h"

namespace {

using portalsim::FileExtent;
using portalsim::FileOrderHash;

struct Fixture {
  portalsim::test::TempDir t;
  std::string path;
  int fd = -1;
  std::string image;  // the finished file
  std::vector<FileExtent> extents;

  // A file of `n` random bytes ("metadata") with extents of random sizes and gaps, the
  // extents' bytes zero on disk until written; the last extent partly filled.
  explicit Fixture(unsigned seed) {
    std::mt19937 rng(seed);
    path = (t.w() / "f.bin").string();
    uint64_t at = 1 + rng() % 3000;
    for (int i = 0; i < 12; ++i) {
      const uint64_t size = 1 + rng() % 5000;
      extents.push_back({at, size, i == 11 ? size / 2 + 1 : size});
      at += size + (rng() % 3 == 0 ? 0 : rng() % 700);
    }
    image.resize(at + rng() % 900);
    for (char& c : image) c = static_cast<char>(rng());
    std::string disk = image;
    for (const FileExtent& x : extents) {
      std::fill(image.begin() + static_cast<long>(x.address + x.filled),
                image.begin() + static_cast<long>(x.address + x.size), '\0');
      std::fill(disk.begin() + static_cast<long>(x.address), disk.begin() + static_cast<long>(x.address + x.size),
                '\0');
    }
    fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
    EXPECT_GE(fd, 0);
    EXPECT_EQ(::pwrite(fd, disk.data(), disk.size(), 0), static_cast<ssize_t>(disk.size()));
  }
  ~Fixture() { ::close(fd); }

  // Extent e's bytes, cut in pieces of at most `piece`: (extent, offset, length).
  std::vector<std::array<uint64_t, 3>> pieces(uint64_t piece) const {
    std::vector<std::array<uint64_t, 3>> p;
    for (size_t e = 0; e < extents.size(); ++e)
      for (uint64_t at = 0; at < extents[e].filled; at += piece)
        p.push_back({e, at, std::min(piece, extents[e].filled - at)});
    return p;
  }
  void feed(FileOrderHash& h, const std::array<uint64_t, 3>& p) const {
    const std::string_view bytes(image.data() + extents[p[0]].address + p[1], p[2]);
    ASSERT_EQ(::pwrite(fd, bytes.data(), bytes.size(), static_cast<off_t>(extents[p[0]].address + p[1])),
              static_cast<ssize_t>(bytes.size()));
    h.feed(p[0], p[1], bytes);
  }
  uint64_t expected() const { return XXH3_64bits(image.data(), image.size()); }
};

// Pieces in an order that keeps each extent's pieces in order but interleaves extents at random.
std::vector<std::array<uint64_t, 3>> shuffled(std::vector<std::array<uint64_t, 3>> p, std::mt19937& rng) {
  std::vector<std::vector<std::array<uint64_t, 3>>> by_extent;
  for (const auto& x : p) {
    if (by_extent.size() <= x[0]) by_extent.resize(x[0] + 1);
    by_extent[x[0]].push_back(x);
  }
  std::vector<size_t> next(by_extent.size(), 0);
  std::vector<std::array<uint64_t, 3>> out;
  while (out.size() < p.size()) {
    const size_t e = rng() % by_extent.size();
    if (next[e] < by_extent[e].size()) out.push_back(by_extent[e][next[e]++]);
  }
  return out;
}

TEST(FileOrderHash, InFileOrderIsTheFilesXxh3) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    Fixture f(seed);
    FileOrderHash h(f.fd, f.path, f.extents, f.image.size());
    h.start();
    for (const auto& p : f.pieces(700)) f.feed(h, p);
    EXPECT_EQ(h.position(), f.image.size());
    EXPECT_EQ(h.finish(), f.expected()) << "seed " << seed;
  }
}

TEST(FileOrderHash, AnyOrderAcrossExtentsGivesTheSameHash) {
  std::mt19937 rng(7);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    Fixture f(seed);
    FileOrderHash h(f.fd, f.path, f.extents, f.image.size());
    h.start();
    for (const auto& p : shuffled(f.pieces(300 + seed * 50), rng)) f.feed(h, p);
    EXPECT_EQ(h.finish(), f.expected()) << "seed " << seed;
  }
}

TEST(FileOrderHash, ResumedFromItsPositionGoesOnToTheSameHash) {
  std::mt19937 rng(11);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    Fixture f(seed);
    const auto order = shuffled(f.pieces(400), rng);
    const size_t stop = order.size() / 3 + seed % 5;
    uint64_t position = 0, digest = 0;
    portalsim::FileState held;
    {
      FileOrderHash h(f.fd, f.path, f.extents, f.image.size());
      h.start();
      for (size_t i = 0; i < stop; ++i) f.feed(h, order[i]);
      position = h.position();
      digest = h.digest();
      held = h.held("held");
    }
    // What a resumed run does: hash the file up to the position, feed again what was held.
    FileOrderHash r(f.fd, f.path, f.extents, f.image.size());
    r.skip_to(position, 2);
    EXPECT_EQ(r.digest(), digest);
    std::vector<std::array<uint64_t, 3>> done(order.begin(), order.begin() + static_cast<long>(stop));
    std::sort(done.begin(), done.end());
    for (const auto& p : done)
      if (f.extents[p[0]].address + p[1] >= position) f.feed(r, p);
    EXPECT_EQ(r.held("held").bytes, held.bytes);
    EXPECT_EQ(r.held("held").xxh3, held.xxh3);
    for (size_t i = stop; i < order.size(); ++i) f.feed(r, order[i]);
    EXPECT_EQ(r.finish(), f.expected()) << "seed " << seed;
  }
}

TEST(FileOrderHash, RefusesAPositionItNeverStopsAtAndPiecesOutOfOrder) {
  Fixture f(3);
  FileOrderHash h(f.fd, f.path, f.extents, f.image.size());
  // Inside the bytes before the first extent, and past the last extent's filled bytes.
  EXPECT_THROW(h.skip_to(f.extents[0].address - 1, 1), portalsim::OutputError);
  EXPECT_THROW(h.skip_to(f.extents.back().address + f.extents.back().filled, 1), portalsim::OutputError);
  FileOrderHash g(f.fd, f.path, f.extents, f.image.size());
  g.start();
  const std::string bytes(10, 'x');
  EXPECT_THROW(g.feed(2, 5, bytes), std::logic_error) << "an extent's pieces must come in order";
  EXPECT_THROW(g.finish(), std::logic_error) << "finished before every extent was filled";
}

}  // namespace
