// Streaming input and output: AppendFile's direct writes (and their fallback through the
// page cache) and ScenarioListFile's rows read a piece at a time.
#include <gtest/gtest.h>
#include <unistd.h>
#include <xxhash.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "base/sizes.h"
#include "run_binary.h"
#include "scene/scenario_list.h"
#include "sink/append_file.h"
#include "support.h"

namespace portalsim {
namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// A fresh folder under `root`, removed afterwards.
struct Folder {
  fs::path path;
  explicit Folder(const fs::path& root) {
    path = root / ("portalsim-stream-" + std::to_string(::getpid()) + "-" +
                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Folder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// The folders AppendFile is tried in: a tmpfs and a disk (the build tree's file system).
std::vector<fs::path> roots() {
  std::vector<fs::path> r;
  if (fs::is_directory("/dev/shm")) r.push_back("/dev/shm");
  r.push_back(fs::temp_directory_path());
  r.push_back(fs::current_path());
  return r;
}

struct RefuseReset {
  ~RefuseReset() { AppendFile::refuse_direct_for_tests(AppendFile::RefuseDirect::no); }
};

using Refuse = AppendFile::RefuseDirect;

// Appends of every size (a byte to several buffers' worth) with checkpoints between them:
// each state() is the bytes so far, which the file then holds; a file left unfinished holds
// exactly its bytes; a resumed one goes on from a checkpoint as if never stopped; a
// finished one is the bytes, and nothing after them.
TEST(AppendFile, DirectOrBufferedTheFileIsTheBytesAtEveryCheckpoint) {
  RefuseReset reset;
  std::mt19937_64 rng(7);
  std::string data(13u << 20, '\0');
  for (char& c : data) c = static_cast<char>(rng());
  const std::vector<size_t> sizes{1, 4095, 4096, 4097, 100, 3u << 20, 5u << 20, 12345, 1, 7};
  for (const fs::path& root : roots())
    for (Refuse how : {Refuse::no, Refuse::at_open, Refuse::at_write}) {
      SCOPED_TRACE(root.string() + " refuse " + std::to_string(static_cast<int>(how)));
      AppendFile::refuse_direct_for_tests(how);
      Folder dir(root);
      const fs::path partial = dir.path / "t.bin.partial";
      FileState mid;
      {
        AppendFile f(dir.path.string(), "t.bin");
        size_t at = 0;
        for (size_t k = 0; k < sizes.size(); ++k) {
          f.append(data.data() + at, sizes[k]);
          at += sizes[k];
          const FileState s = f.state();
          ASSERT_EQ(s.bytes, at);
          EXPECT_EQ(s.xxh3, XXH3_64bits(data.data(), at));
          const std::string on_disk = read_all(partial);
          ASSERT_GE(on_disk.size(), at);
          EXPECT_TRUE(on_disk.compare(0, at, data, 0, at) == 0) << "after append " << k;
          if (k == 5) mid = s;
        }
        if (how != Refuse::no) {
          EXPECT_FALSE(f.direct());
        }
      }
      // Dropped unfinished (a run stopped cleanly): exactly the bytes appended.
      size_t total = 0;
      for (size_t n : sizes) total += n;
      EXPECT_EQ(fs::file_size(partial), total);
      // A run killed after the checkpoint `mid`, with a padded last block past it.
      fs::resize_file(partial, total + 3000);
      {
        AppendFile f(dir.path.string(), "t.bin", &mid);
        f.append(data.data() + mid.bytes, 777);
        f.append(data.data() + mid.bytes + 777, (7u << 20) - 777);
        EXPECT_EQ(f.state().xxh3, XXH3_64bits(data.data(), mid.bytes + (7u << 20)));
        f.finish();
      }
      EXPECT_EQ(read_all(dir.path / "t.bin"), data.substr(0, mid.bytes + (7u << 20)));
      EXPECT_FALSE(fs::exists(partial));
    }
}

// On a disk, direct writes are taken; refused at open or at the first write, the file
// goes through the page cache.
TEST(AppendFile, FallsBackToThePageCacheWhereDirectWritesAreRefused) {
  RefuseReset reset;
  Folder dir(fs::current_path());
  {
    AppendFile f(dir.path.string(), "a");
    f.append(std::string(5000, 'x'));
    f.state();
    EXPECT_TRUE(f.direct()) << "the build folder's file system refused O_DIRECT";
  }
  AppendFile::refuse_direct_for_tests(Refuse::at_write);
  {
    AppendFile f(dir.path.string(), "b");
    EXPECT_TRUE(f.direct());
    f.append(std::string(5000, 'y'));
    f.state();
    EXPECT_FALSE(f.direct());
    f.finish();
  }
  EXPECT_EQ(read_all(dir.path / "b"), std::string(5000, 'y'));
}

// ---------------------------------------------------------------------------------------------
// Scenario lists.

const std::string kHeader =
    "subject,region1,region2,region3,region4,region5,region6,region7,region8,region9,region10,region11,"
    "region12,region13,label";

std::string row(int subject, const std::string& first, const std::string& label) {
  return std::to_string(subject) + "," + first + ",none,none,none,none,none,none,none,none,none,none,none,none," +
         label;
}

struct PieceReset {
  ~PieceReset() { ScenarioListFile::set_piece_bytes_for_tests(kIoPieceBytes, 1u << 16); }
};

fs::path write_list(const Folder& dir, const std::string& text) {
  const fs::path p = dir.path / "list.csv";
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

// Read in pieces of a few bytes (rows, quoted fields and CRLFs straddle them) and from any
// row (marks every 3 rows), the rows are what the whole text parses to.
TEST(ScenarioListFile, RowsStraddlingPiecesReadAsTheWholeText) {
  PieceReset reset;
  std::string text = "\xEF\xBB\xBF# a comment\n\n" + kHeader + "\r\n";
  for (int i = 0; i < 40; ++i) {
    if (i % 7 == 3) text += "# between rows, \"quoted\"\n\n";
    const char* first[] = {"\"gun:v\"", " \"gun\" ", "rod:v", "none"};
    text += row(1 + i % 3, first[i % 4], i % 3 ? "\"no\"" : "yes") + (i % 5 ? "\n" : "\r\n");
  }
  const std::vector<Scenario> whole = parse_scenario_list(test::catalogue(), text, "list.csv");
  ASSERT_EQ(whole.size(), 40u);
  Folder dir(fs::temp_directory_path());
  const fs::path p = write_list(dir, text);
  for (size_t piece : {1u, 5u, 64u, 1u << 20}) {
    ScenarioListFile::set_piece_bytes_for_tests(piece, 3);
    const ScenarioListFile list(test::catalogue(), p.string());
    ASSERT_EQ(list.size(), 40u);
    for (uint64_t at = 0; at < 40; at += 1)
      for (size_t n : {1u, 4u, 40u}) {
        if (at + n > 40) continue;
        std::vector<Scenario> got(n);
        list.read(at, n, 2, got.data(), nullptr);
        for (size_t i = 0; i < n; ++i) {
          EXPECT_EQ(got[i].subject, whole[at + i].subject) << "piece " << piece << " row " << at + i;
          EXPECT_EQ(got[i].objects, whole[at + i].objects) << "piece " << piece << " row " << at + i;
          EXPECT_EQ(got[i].label, whole[at + i].label) << "piece " << piece << " row " << at + i;
        }
      }
  }
}

// The message of the InputError that reading rows [at, at + n) of `list` throws, on two
// threads; "" when the rows are accepted.
std::string read_error(const ScenarioListFile& list, uint64_t at, size_t n) {
  std::vector<Scenario> got(n);
  try {
    list.read(at, n, 2, got.data(), nullptr);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A quoted field left open at its line's end (a line break in a field) is refused on its
// line, wherever the pieces fall; so is any bad row, the first of several on any thread.
TEST(ScenarioListFile, BadRowsAreNamedByTheirLine) {
  PieceReset reset;
  Folder dir(fs::temp_directory_path());
  std::string text = kHeader + "\n";
  for (int i = 0; i < 3000; ++i) text += row(1, "gun", "yes") + "\n";
  const std::string open_quote = text + "1,\"gun\n,none\",none,none,none,none,none,none,none,none,none,none,none,yes\n";
  for (size_t piece : {3u, 4096u}) {
    ScenarioListFile::set_piece_bytes_for_tests(piece, 1000);
    const ScenarioListFile list(test::catalogue(), write_list(dir, open_quote).string());
    const std::string e = read_error(list, 0, list.size());
    EXPECT_NE(e, "") << "a quoted field with a line break was accepted";
    EXPECT_TRUE(test::has(e, "list.csv:3002: column 2: a quoted field is not closed on its line")) << e;
  }
  // Two bad rows, in the halves two threads parse: the first is named.
  std::string two = kHeader + "\n";
  for (int i = 0; i < 3000; ++i)
    two += (i == 2000 ? row(1, "laser", "yes") : i == 900 ? row(9, "gun", "yes") : row(1, "gun", "no")) + "\n";
  const ScenarioListFile list(test::catalogue(), write_list(dir, two).string());
  const std::string first = read_error(list, 0, list.size());
  EXPECT_NE(first, "") << "bad rows were accepted";
  EXPECT_TRUE(test::has(first, "list.csv:902: subject: \"9\"")) << first;
  // From a mark past the first bad row, the second is met.
  const std::string second = read_error(list, 1500, 1000);
  EXPECT_NE(second, "") << "a bad row was accepted";
  EXPECT_TRUE(test::has(second, "list.csv:2002: region1: unknown object \"laser\"")) << second;
}

}  // namespace
}  // namespace portalsim
