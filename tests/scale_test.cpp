// Past one process: portalsim merge of --shard parts, and generate under mpirun (Open MPI,
// as root with --allow-run-as-root, more ranks than cores with --oversubscribe). Every
// check is byte for byte against one process making the whole data set.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <map>

#include "run_binary.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;
using Args = std::vector<std::string>;

const char* const kMpirun = "/usr/bin/mpirun";

Args cat(Args a, const Args& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

Result ps(const TempDir& t, const Args& args) { return finish(start(t.cap(), args), 300); }

Running start_mpi(const TempDir& t, int ranks, const Args& args) {
  return start_program(
      t.cap(), kMpirun,
      cat({"--oversubscribe", "--allow-run-as-root", "-np", std::to_string(ranks), portalsim::test::kBinary}, args));
}

Args gen(const Args& spec, const fs::path& out) { return cat(cat({"generate"}, spec), {"--out", out.string()}); }

void ExpectOk(const Result& r) {
  EXPECT_TRUE(r.exited && r.status == 0 && !r.timed_out) << describe(r);
  EXPECT_EQ(r.err.find("error"), std::string::npos) << describe(r);
}

size_t occurrences(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) ++n;
  return n;
}

// Every regular file under `dir` (hidden ones too): relative path -> bytes.
std::map<std::string, std::string> tree(const fs::path& dir) {
  std::map<std::string, std::string> m;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) m[fs::relative(e.path(), dir).string()] = slurp(e.path());
  return m;
}

void ExpectSameBytes(const fs::path& whole, const fs::path& other) {
  const auto a = tree(whole), b = tree(other);
  ASSERT_FALSE(a.empty());
  std::vector<std::string> na, nb;
  for (const auto& [k, v] : a) na.push_back(k);
  for (const auto& [k, v] : b) nb.push_back(k);
  ASSERT_EQ(na, nb) << whole << " and " << other << " hold different files";
  for (const auto& [k, v] : a)
    EXPECT_TRUE(v == b.at(k)) << k << " differs: " << v.size() << " bytes in " << whole << ", " << b.at(k).size()
                              << " in " << other;
}

// Every output kind: the four tables and data.h5 (with randomised objects' transforms);
// image folders; image tensors as .npy.
const std::vector<Args> kSpecs{
    {"--count", "240", "--seed", "7", "--rule", "gun", "--what", "both", "--format", "arff,csv,npy,h5", "--batch", "32",
     "--rotate", "-20..20", "--scale", "0.9..1.1", "--flip", "on", "--quiet"},
    {"--count", "90", "--seed", "8", "--rule", "iron-rod", "--what", "both", "--format", "csv", "--batch", "16",
     "--quiet"},
    {"--count", "120", "--seed", "9", "--what", "images", "--format", "npy", "--batch", "16", "--quiet"}};
// Mpi.ThreeRanksEqualOneProcessInEveryFormat under the sanitizers: the first spec alone, its
// ranks' processes several times slower there; the parts of every kind are joined by
// merge's code, which Merge.* runs there on every spec.
const size_t kMpiSpecs = kSanitized ? 1 : kSpecs.size();

TEST(Merge, ThreeShardsInAnyOrderEqualTheWholeRun) {
  TempDir t;
  for (size_t s = 0; s < kSpecs.size(); ++s) {
    SCOPED_TRACE("spec " + std::to_string(s));
    const fs::path whole = t.w() / ("whole" + std::to_string(s)), merged = t.w() / ("merged" + std::to_string(s));
    ExpectOk(ps(t, gen(kSpecs[s], whole)));
    Args parts;
    for (int i = 0; i < 3; ++i) {
      const fs::path p = t.w() / ("part" + std::to_string(s) + "-" + std::to_string(i));
      ExpectOk(ps(t, gen(cat(kSpecs[s], {"--shard", std::to_string(i) + "/3"}), p)));
      parts.insert(parts.begin(), p.string());  // 2, 1, 0: order does not matter
    }
    const Result m = ps(t, cat(cat({"merge"}, parts), {"--out", merged.string()}));
    ExpectOk(m);
    EXPECT_NE(m.out.find("3 parts joined"), std::string::npos) << describe(m);
    ExpectSameBytes(whole, merged);
    // Parts are read, never changed: a second merge gives the same again.
    ExpectOk(ps(t, cat(cat({"merge"}, parts), {"--out", (merged.string() + "b")})));
    ExpectSameBytes(whole, merged.string() + "b");
  }
  // Shards of different k that tile the range join as well: 0/2 with 2/4 and 3/4.
  const fs::path a = t.w() / "h0", b = t.w() / "q2", c = t.w() / "q3", m = t.w() / "mixed";
  ExpectOk(ps(t, gen(cat(kSpecs[0], {"--shard", "0/2"}), a)));
  ExpectOk(ps(t, gen(cat(kSpecs[0], {"--shard", "2/4"}), b)));
  ExpectOk(ps(t, gen(cat(kSpecs[0], {"--shard", "3/4"}), c)));
  ExpectOk(ps(t, {"merge", c.string(), a.string(), b.string(), "--out", m.string()}));
  ExpectSameBytes(t.w() / "whole0", m);
}

// A refused merge: exit 3 (bad input) or 4 (output), a message naming every needle, and no
// output folder left behind.
void ExpectRefused(const Result& r, const fs::path& out, int status, const std::vector<std::string>& needles) {
  EXPECT_TRUE(r.exited && r.status == status) << describe(r);
  for (const std::string& n : needles) EXPECT_NE(r.err.find(n), std::string::npos) << n << "\n" << describe(r);
  EXPECT_EQ(r.err.find("Assertion"), std::string::npos) << describe(r);
  std::error_code ec;
  EXPECT_FALSE(fs::exists(out / "manifest.json", ec)) << describe(r);
}

TEST(Merge, RefusesPartsThatDoNotFit) {
  TempDir t;
  const Args spec{"--count", "100", "--seed", "3", "--format", "csv", "--quiet"};
  const auto part = [&](const std::string& name, const Args& s, const std::string& shard) {
    const fs::path p = t.w() / name;
    ExpectOk(ps(t, gen(cat(s, {"--shard", shard}), p)));
    return p.string();
  };
  const std::string p0 = part("p0", spec, "0/3"), p1 = part("p1", spec, "1/3"), p2 = part("p2", spec, "2/3");
  const std::string other_seed = part("seed4", {"--count", "100", "--seed", "4", "--format", "csv", "--quiet"}, "1/3");
  const std::string other_format = part("arff", {"--count", "100", "--seed", "3", "--quiet"}, "1/3");
  const std::string half = part("half", spec, "0/2");
  const fs::path out = t.w() / "out";

  // The message reads plainly: which part, against which, what differs and how (issue 36).
  ExpectRefused(
      ps(t, {"merge", p0, other_seed, p2, "--out", out.string()}), out, 3,
      {"part " + other_seed + " differs from the first part " + p0 + " in spec.seed: 4 here, 3 in the first"});
  ExpectRefused(ps(t, {"merge", p0, other_format, p2, "--out", out.string()}), out, 3, {"arff", "spec.format"});
  ExpectRefused(ps(t, {"merge", p0, p2, "--out", out.string()}), out, 3, {"no part holds scenarios [33, 66)"});
  ExpectRefused(ps(t, {"merge", p0, p1, "--out", out.string()}), out, 3, {"[66, 100)"});
  ExpectRefused(ps(t, {"merge", p0, p1, half, p2, "--out", out.string()}), out, 3, {"both hold scenarios"});
  ExpectRefused(ps(t, {"merge", p0, p0, p1, p2, "--out", out.string()}), out, 3, {"both hold scenarios [0, 33)"});
  // An unfinished part: no manifest.
  fs::create_directories(t.w() / "unfinished");
  ExpectRefused(ps(t, {"merge", p0, (t.w() / "unfinished").string(), "--out", out.string()}), out, 3,
                {"unfinished", "no manifest.json"});
  // A part whose table was cut short.
  fs::copy(p1, t.w() / "cut", fs::copy_options::recursive);
  fs::resize_file(t.w() / "cut" / "features.csv", fs::file_size(t.w() / "cut" / "features.csv") - 10);
  ExpectRefused(ps(t, {"merge", p0, (t.w() / "cut").string(), p2, "--out", out.string()}), out, 3, {"cut"});
  // A manifest naming an output outside the part, and a FIFO where a table should be:
  // refused, never followed or waited on.
  fs::copy(p1, t.w() / "evil", fs::copy_options::recursive);
  std::string m = slurp(t.w() / "evil" / "manifest.json");
  m.replace(m.find("\"features.csv\""), 14, "\"../escape.csv\"");
  spit(t.w() / "evil" / "manifest.json", m);
  ExpectRefused(ps(t, {"merge", p0, (t.w() / "evil").string(), p2, "--out", out.string()}), out, 3,
                {"evil", "not a plain file name"});
  EXPECT_FALSE(fs::exists(t.w() / "escape.csv.partial"));
  fs::copy(p1, t.w() / "fifo", fs::copy_options::recursive);
  fs::remove(t.w() / "fifo" / "features.csv");
  ASSERT_EQ(::mkfifo((t.w() / "fifo" / "features.csv").c_str(), 0644), 0);
  ExpectRefused(ps(t, {"merge", p0, (t.w() / "fifo").string(), p2, "--out", out.string()}), out, 3,
                {"fifo", "features.csv"});
  // An output folder that holds something.
  fs::create_directories(t.w() / "full");
  spit(t.w() / "full" / "keep.txt", "mine");
  ExpectRefused(ps(t, {"merge", p0, p1, p2, "--out", (t.w() / "full").string()}), t.w() / "full", 4, {"not empty"});
  EXPECT_EQ(slurp(t.w() / "full" / "keep.txt"), "mine");
  EXPECT_FALSE(fs::exists(out)) << "a refused merge leaves no folder behind";
}

TEST(Mpi, ThreeRanksEqualOneProcessInEveryFormat) {
  TempDir t;
  for (size_t s = 0; s < kMpiSpecs; ++s) {
    SCOPED_TRACE("spec " + std::to_string(s));
    const fs::path whole = t.w() / ("whole" + std::to_string(s)), ranked = t.w() / ("mpi" + std::to_string(s));
    ExpectOk(ps(t, gen(kSpecs[s], whole)));
    const Result r = finish(start_mpi(t, 3, gen(kSpecs[s], ranked)), 600);
    ExpectOk(r);
    // One summary for the whole job, from rank 0.
    EXPECT_EQ(occurrences(r.out, ranked.string() + ":"), 1u) << describe(r);
    EXPECT_NE(r.out.find("3 ranks"), std::string::npos) << describe(r);
    ExpectSameBytes(whole, ranked);
  }
}

long long part_next(const fs::path& part) {
  const std::string c = slurp(part / ".portalsim" / "checkpoint.json");
  const size_t n = c.find("\"next\":");
  const size_t b = c.find("\"begin\":");
  if (n == std::string::npos || b == std::string::npos) return -1;
  return std::atoll(c.c_str() + n + 7) - std::atoll(c.c_str() + b + 8);
}

TEST(Mpi, KilledRankEndsTheJobAndResumeFinishesItOnAnyNumberOfRanks) {
  TempDir t;
  const Args spec{"--count", "1200", "--seed", "5", "--what", "both", "--format", "csv", "--batch", "16", "--quiet"};
  const fs::path whole = t.w() / "whole";
  ExpectOk(ps(t, gen(spec, whole)));
  for (int resume_ranks : {1, 2}) {
    SCOPED_TRACE("resumed on " + std::to_string(resume_ranks) + " ranks");
    const fs::path dir = t.w() / ("killed" + std::to_string(resume_ranks)),
                   part = dir / ".portalsim" / "parts" / "1-of-3";
    const Running job = start_mpi(t, 3, gen(spec, dir));
    // Rank 1 holds its part's lock, which names its PID; kill it once it has checkpointed.
    pid_t victim = -1;
    wait_until(
        [&] {
          if (part_next(part) > 0) victim = static_cast<pid_t>(std::atol(slurp(part / ".portalsim" / "lock").c_str()));
          return victim > 0 || has_ended(job);
        },
        60);
    ASSERT_GT(victim, 0) << "rank 1 never checkpointed\n" << describe(finish(job, 600));
    ASSERT_EQ(::kill(victim, SIGKILL), 0);
    const Result k = finish(job, 600);
    // Rank 1's part is scenarios [400, 800): the kill must have come in its middle.
    const long long done = part_next(part);
    EXPECT_TRUE(done > 0 && done < 400) << "rank 1 was killed with " << done << " of its 400 scenarios written";
    EXPECT_TRUE(k.exited && k.status != 0) << describe(k);
    EXPECT_NE((k.out + k.err).find("rank 1"), std::string::npos) << "the message names the rank\n" << describe(k);
    EXPECT_FALSE(fs::exists(dir / "manifest.json"));
    // Without --resume the folder is refused, and said why.
    const Result again = ps(t, gen(spec, dir));
    EXPECT_TRUE(again.exited && again.status == 4) << describe(again);
    EXPECT_NE(again.err.find("--resume"), std::string::npos) << describe(again);

    const Result r = resume_ranks == 1 ? ps(t, gen(cat(spec, {"--resume"}), dir))
                                       : finish(start_mpi(t, resume_ranks, gen(cat(spec, {"--resume"}), dir)), 600);
    ExpectOk(r);
    ExpectSameBytes(whole, dir);
  }
}

TEST(Mpi, AFailingRankStopsEveryRankAndIsNamed) {
  TempDir t;
  const fs::path dir = t.w() / "out";
  // Rank 2's part folder is a file: rank 2 cannot start its part.
  fs::create_directories(dir / ".portalsim" / "parts");
  spit(dir / ".portalsim" / "parts" / "2-of-3", "in the way");
  const Result r = finish(
      start_mpi(t, 3, gen({"--count", "300", "--seed", "1", "--format", "csv", "--batch", "16", "--quiet"}, dir)), 300);
  EXPECT_TRUE(r.exited && r.status == 4) << describe(r);
  EXPECT_NE(r.err.find("rank 2: "), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("2-of-3"), std::string::npos) << describe(r);
  EXPECT_EQ(occurrences(r.err, "portalsim: error:"), 1u) << "rank 0 alone reports\n" << describe(r);
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));
}

// The binary links no MPI: under a launcher it loads its MPI module, and where that is
// missing it stops before writing, naming the module and where it looked.
TEST(Mpi, AMissingMpiModuleIsNamed) {
  TempDir t;
  const fs::path alone = t.w() / "bin" / "portalsim", out = t.w() / "out";
  fs::create_directories(alone.parent_path());
  fs::copy_file(portalsim::test::kBinary, alone);
  const Result r = finish(
      start_program(t.cap(), "/usr/bin/env",
                    {"OMPI_COMM_WORLD_SIZE=2", alone.string(), "generate", "--count", "4", "--out", out.string()}),
      60);
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5) << "5: the machine";
  EXPECT_NE(r.err.find("started by an MPI launcher, but this portalsim has no MPI module libportalsim_mpi.so"),
            std::string::npos);
  EXPECT_NE(r.err.find((alone.parent_path() / "libportalsim_mpi.so").string()), std::string::npos) << "where it looked";
  EXPECT_FALSE(fs::exists(out));
}

TEST(Mpi, AnOutputMergeCannotJoinIsRefusedBeforeAnyRankWrites) {
  TempDir t;
  const fs::path dir = t.w() / "out";
  const Result r =
      finish(start_mpi(t, 2, gen({"--count", "20", "--what", "images", "--annotations", "--quiet"}, dir)), 300);
  EXPECT_TRUE(r.exited && r.status != 0) << describe(r);
  EXPECT_NE(r.err.find("--annotations: not with an MPI launch: merge cannot join COCO annotations"), std::string::npos)
      << describe(r);
  EXPECT_FALSE(fs::exists(dir / "manifest.json"));
}

}  // namespace
}  // namespace portalsim::test
