// Hostile input and output folders (issue 10): the input layer's checks, the fuzz
// corpus and every crash the fuzzers found replayed, special files, exit codes, the
// folder lock, resuming, and what an error must never delete.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "base/error.h"
#include "fuzz/targets.h"
#include "io/contained.h"
#include "io/input_file.h"
#include "io/toml_input.h"
#include "run_binary.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;
using Args = std::vector<std::string>;

Result run(const TempDir& t, const Args& args, int limit_s = 60) {
  return portalsim::test::finish(portalsim::test::start(t.cap(), args), limit_s);
}

// The message of the InputError that check_text throws, or "" when it accepts.
std::string text_error(std::string_view text, portalsim::io::Bom bom = portalsim::io::Bom::refuse) {
  try {
    portalsim::io::check_text(text, "f.txt", bom);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kHeader =
    "subject,region1,region2,region3,region4,region5,region6,region7,region8,region9,region10,region11,region12,"
    "region13";

// Runs `portalsim ARGS` and expects exit `code` with one message naming every needle.
void ExpectExit(const Result& r, int code, const std::vector<std::string>& needles) {
  SCOPED_TRACE(describe(r));
  EXPECT_FALSE(r.timed_out) << "must not hang";
  ASSERT_TRUE(r.exited) << "must not crash";
  EXPECT_EQ(r.status, code);
  for (const std::string& n : needles) EXPECT_TRUE(has(r.err, n)) << "the message must name " << n;
}

// ---------------------------------------------------------------------------------------------
// The byte rules every text input goes through.

TEST(InputText, RejectsNulControlBytesAndInvalidUtf8WithLineAndColumn) {
  EXPECT_EQ(text_error("a = 1\nb = \"x\"\n"), "");
  EXPECT_EQ(text_error("tab\there, \xC3\xA9 and \xE2\x82\xAC\r\n"), "") << "tab, UTF-8 and CRLF are text";
  EXPECT_TRUE(has(text_error(std::string("ok\ngu", 5) + std::string(1, '\0') + "n"), "f.txt:2:3: NUL byte"));
  EXPECT_TRUE(has(text_error("a\x01"), "f.txt:1:2: control character 0x01"));
  EXPECT_TRUE(has(text_error("a\x7f"), "control character 0x7F"));
  EXPECT_TRUE(has(text_error("a\rb"), "f.txt:1:2: control character 0x0D")) << "a CR alone is not a line end";
  EXPECT_TRUE(has(text_error("\xC3\xA9x\xFF"), "f.txt:1:3: invalid UTF-8 (byte 0xFF)"));
  EXPECT_TRUE(has(text_error("\xC0\x80"), "invalid UTF-8")) << "overlong NUL";
  EXPECT_TRUE(has(text_error("\xED\xA0\x80"), "invalid UTF-8")) << "a surrogate";
  EXPECT_TRUE(has(text_error("\xE2\x82"), "invalid UTF-8")) << "truncated sequence";
  EXPECT_TRUE(has(text_error("\xC2\x85"), "control character 0x85")) << "C1 controls";
}

TEST(InputText, BomRefusedOrSkippedAndLinesCapped) {
  EXPECT_TRUE(has(text_error("\xEF\xBB\xBF"
                             "a"),
                  "f.txt:1:1: byte-order mark"));
  EXPECT_EQ(text_error("\xEF\xBB\xBF"
                       "a",
                       portalsim::io::Bom::skip),
            "");
  EXPECT_EQ(portalsim::io::check_text("\xEF\xBB\xBF"
                                      "a",
                                      "f", portalsim::io::Bom::skip),
            "a");
  EXPECT_TRUE(has(text_error("a\xEF\xBB\xBF", portalsim::io::Bom::skip), "inside the text"));
  EXPECT_EQ(text_error(std::string(portalsim::io::kMaxLineBytes, 'x')), "");
  EXPECT_TRUE(has(text_error("a\n" + std::string(portalsim::io::kMaxLineBytes + 1, 'x')), "f.txt:2:"))
      << "a line one byte over the cap";
}

TEST(InputToml, NestingIsCappedBeforeTomlPlusPlusSeesIt) {
  const auto nested = [](int depth) {
    std::string open, close;
    for (int i = 0; i < depth; ++i) open += "[\n", close += "]\n";
    return "a = " + open + close;
  };
  EXPECT_NO_THROW(portalsim::io::parse_toml(nested(portalsim::io::kMaxTomlDepth), "n.toml"));
  try {
    portalsim::io::parse_toml(nested(100000), "n.toml");
    ADD_FAILURE() << "100,000 levels accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "n.toml:33:1: arrays and tables nested deeper than 32")) << e.what();
  }
  // Brackets inside strings and comments, and [table] headers, are not nesting.
  const std::string quiet = "s = \"" + std::string(100, '[') + "\" # " + std::string(100, '{') + "\nt = '''\n" +
                            std::string(100, '[') + "'''\n[x]\n[[y]]\n";
  EXPECT_NO_THROW(portalsim::io::parse_toml(quiet, "q.toml"));
  EXPECT_THROW(portalsim::io::parse_toml("a = 1\na = 2\n", "d.toml"), InputError) << "duplicate keys";
  // Dotted keys and headers nest tables too: 32,000 parts crashed toml++ (SIGSEGV).
  std::string parts = "a";
  for (int i = 0; i < 32000; ++i) parts += ".a";
  EXPECT_THROW(portalsim::io::parse_toml(parts + " = 1\n", "k.toml"), InputError);
  EXPECT_THROW(portalsim::io::parse_toml("[" + parts + "]\n", "h.toml"), InputError);
  EXPECT_THROW(portalsim::io::parse_toml("t = {" + parts + " = 1}\n", "i.toml"), InputError);
  EXPECT_NO_THROW(portalsim::io::parse_toml("[a.b.c]\nd.e.f = [[1], {g.h = 2}]\n", "ok.toml"));
}

TEST(InputToml, UnknownKeyNamesTheNearestKnownOne) {
  const toml::table t = portalsim::io::parse_toml("mmw_upper = 1\nmmw_uper = 2\n", "k.toml");
  try {
    portalsim::io::reject_unknown_keys(t, {"mmw_upper", "mmw_lower"}, "k.toml", "subjects[1]");
    ADD_FAILURE() << "mmw_uper accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "k.toml:2:")) << e.what();
    EXPECT_TRUE(has(e.what(), "subjects[1].mmw_uper: unknown key (did you mean mmw_upper?)")) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// The fuzz corpus and every crash found, through the same entry points as the fuzzers.

TEST(InputFuzzCorpus, EverySeedAndCrashParsesOrFailsWithInputError) {
  const fs::path root = fs::path(PORTALSIM_SOURCE_DIR) / "tests" / "fuzz";
  for (const std::string& target : portalsim::fuzz::target_names()) {
    int seeds = 0, parsed = 0;
    for (const char* kind : {"corpus", "crashes"}) {
      const fs::path dir = root / kind / target;
      if (std::string(kind) == "corpus") {
        ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing";
      }
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(dir, ec)) {
        SCOPED_TRACE(e.path().string());
        const std::string bytes = slurp(e.path());
        // Anything but InputError escapes and fails the test, as it crashes the fuzzer.
        parsed += portalsim::fuzz::run_target(target, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
        ++seeds;
      }
    }
    EXPECT_GE(seeds, 2) << target << ": the seed corpus must not be empty";
    EXPECT_GE(parsed, 1) << target << ": at least one seed must be valid input";
  }
}

// ---------------------------------------------------------------------------------------------
// Special files: refused, without blocking.

TEST(InputFiles, FifoDeviceFolderAndHugeFilesAreRefusedWithoutBlocking) {
  TempDir t;
  const fs::path fifo = t.w() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path out = t.w() / "out";
  struct Case {
    Args args;
    std::string path, kind;
  };
  const std::vector<Case> cases{
      {{"generate", "--spec", fifo.string()}, fifo.string(), "a FIFO"},
      {{"generate", "--scenarios", fifo.string()}, fifo.string(), "a FIFO"},
      {{"catalogue", "--catalogue", fifo.string()}, fifo.string(), "a FIFO"},
      {{"generate", "--spec", "/dev/zero"}, "/dev/zero", "a device"},
      {{"catalogue", "--catalogue", "/dev/zero"}, "/dev/zero", "a device"},
      {{"generate", "--spec", t.w().string()}, t.w().string(), "a folder"},
  };
  for (const Case& c : cases) {
    Args a = c.args;
    if (a[0] == "generate") a.insert(a.end(), {"--out", out.string(), "--quiet"});
    // A run that blocked on the FIFO would hang: run's limit (a hang detector) ends it,
    // and ExpectExit fails on its status.
    ExpectExit(run(t, a, 20), 3, {c.path, c.kind});
    EXPECT_FALSE(fs::exists(out)) << "nothing is made for a refused input";
  }
  // A sparse file over the documented cap is refused by its size, before it is read.
  const fs::path big = t.w() / "big.toml";
  spit(big, "count = 5\n");
  ASSERT_EQ(::truncate(big.c_str(), static_cast<off_t>(portalsim::io::kMaxTextBytes) + 1), 0);
  ExpectExit(run(t, {"generate", "--spec", big.string(), "--out", out.string()}), 3, {big.string(), "64 MiB"});
}

// ---------------------------------------------------------------------------------------------
// Hostile text through the command line: each names file, line and field; exit 3.

TEST(InputFiles, HostileTextIsRefusedNamingFileLineAndField) {
  TempDir t;
  const fs::path out = t.w() / "out";
  const auto file = [&](const std::string& name, const std::string& text) {
    spit(t.w() / name, text);
    return (t.w() / name).string();
  };
  const std::string empty_row = ",,,,,,,,,,,,";
  struct Case {
    Args args;
    std::vector<std::string> needles;
  };
  const std::string nul = file("nul.csv", kHeader + "\n1,gun" + std::string(1, '\0') + empty_row + "\n");
  const std::string dup = file("dup.csv", kHeader + ",region4\n1" + empty_row + ",,\n");
  std::string levels;
  for (int i = 0; i < 100000; ++i) levels += "[\n";
  const std::string deep = file("deep.toml", "count = " + levels);
  const std::string bom = file("bom.toml",
                               "\xEF\xBB\xBF"
                               "count = 5\n");
  const std::string nan = file("nan.toml", "count = 5\npixel_noise = nan\n");
  const std::string inf = file("inf.toml", "count = 5\njitter = inf\n");
  const std::string big = file("big.toml", "count = 99999999999999\n");
  const std::string twice = file("twice.toml", "count = 5\ncount = 6\n");
  const std::string longf = file("long.csv", kHeader + "\n1," + std::string(300, 'g') + empty_row + "\n");
  // Quoting as RFC 4180 reads it: "gun,none" is one field (no object of that name), not two.
  std::string nones;
  for (int r = 0; r < 12; ++r) nones += ",none";
  const std::string quoted_comma = file("quoted.csv", kHeader + "\n1,\"gun,none\"" + nones + "\n");
  const std::string short_row = file("short.csv", kHeader + "\n1,\"gun,none\",none" + nones.substr(5 * 2) + "\n");
  const std::string stray = file("stray.csv", kHeader + "\n1,gu\"n" + nones + "\n");
  const std::string open = file("open.csv", kHeader + "\n1,none,\"gun" + nones.substr(5) + "\n");
  const std::string after = file("after.csv", kHeader + "\n1,\"gun\"x" + nones + "\n");
  const std::string bad_rule = file("rule.toml", "count = 5\n\nrule = \"gun&\"\n");
  std::string cat = slurp(fs::path(PORTALSIM_SOURCE_DIR) / "scenarios" / "catalogue.toml");
  cat.insert(cat.find("\n", cat.find("[[subjects]]")) + 1, "imagse = { upper = \"u.png\" }\n");
  const std::string typo = file("typo.toml", cat);
  const std::vector<Case> cases{
      {{"generate", "--scenarios", nul}, {nul + ":2:6", "NUL"}},
      {{"generate", "--scenarios", dup}, {dup + ":1", "column 15", "region4", "duplicates column 5"}},
      {{"generate", "--spec", deep}, {deep + ":33:1", "nested deeper than 32"}},
      {{"generate", "--spec", bom}, {bom + ":1:1", "byte-order mark"}},
      {{"generate", "--spec", nan}, {nan + ":2", "pixel_noise", "finite"}},
      {{"generate", "--spec", inf}, {inf + ":2", "jitter", "finite"}},
      {{"generate", "--spec", big}, {big + ":1", "count", "out of range"}},
      {{"generate", "--spec", twice}, {twice + ":2", "count"}},
      {{"generate", "--scenarios", longf}, {longf + ":2", "column 2", "longer than 256"}},
      {{"generate", "--scenarios", quoted_comma}, {quoted_comma + ":2", "region1", "unknown object \"gun,none\""}},
      {{"generate", "--scenarios", short_row}, {short_row + ":2", "expected 14 fields, found 13"}},
      {{"generate", "--scenarios", stray}, {stray + ":2", "column 2", "a quote inside an unquoted field"}},
      {{"generate", "--scenarios", open}, {open + ":2", "column 3", "not closed on its line"}},
      {{"generate", "--scenarios", after}, {after + ":2", "column 2", "after the closing quote"}},
      {{"generate", "--spec", bad_rule}, {bad_rule + ":3: rule", "\"gun&\" at character 5"}},
      {{"catalogue", "--catalogue", typo}, {typo + ":", "subjects[1].imagse", "did you mean images?"}},
  };
  for (const Case& c : cases) {
    Args a = c.args;
    if (a[0] == "generate") a.insert(a.end(), {"--out", out.string(), "--quiet", "--backend", "reference"});
    ExpectExit(run(t, a), 3, c.needles);
    EXPECT_FALSE(fs::exists(out));
  }
  // CRLF and a BOM are what spreadsheets write: accepted in a scenario list.
  const std::string sheet = file("sheet.csv", "\xEF\xBB\xBF" + kHeader + "\r\n1,gun" + empty_row + "\r\n");
  const Result ok =
      run(t, {"generate", "--scenarios", sheet, "--out", out.string(), "--quiet", "--backend", "reference"});
  ExpectExit(ok, 0, {});
  EXPECT_TRUE(has(slurp(out / "scenarios.csv"), "gun")) << slurp(out / "scenarios.csv");
  // The same rule on the command line: a usage error naming the flag.
  const fs::path rule_out = t.w() / "rule-out";
  ExpectExit(run(t, {"generate", "--rule", "gun&", "--count", "5", "--out", rule_out.string(), "--quiet"}), 2,
             {"--rule: \"gun&\" at character 5"});
  EXPECT_FALSE(fs::exists(rule_out));
  // Quoted fields as a spreadsheet may write them, spaces round the quotes, a quote doubled
  // inside one: read as their text ("gun" is gun; "gu""n" is gu"n, a name that, as every
  // object name, is matched without its punctuation: gun).
  fs::remove_all(out);
  const std::string quoted_good =
      file("quoted-good.csv", kHeader + ",label\n\"1\", \"gun\" ,\"gu\"\"n\"" + nones.substr(5) + ",\"yes\"\n");
  ExpectExit(
      run(t, {"generate", "--scenarios", quoted_good, "--out", out.string(), "--quiet", "--backend", "reference"}), 0,
      {});
  EXPECT_TRUE(has(slurp(out / "scenarios.csv"), "1,gun:h,gun:h,none")) << slurp(out / "scenarios.csv");
}

TEST(InputFiles, ImageDeclaringTooManyPixelsIsRefusedBeforeDecoding) {
  TempDir t;
  // A valid PNG header declaring 16384x16384 gray pixels, and a few bytes of data (a
  // seed of the image fuzzer).
  const std::string png =
      slurp(fs::path(PORTALSIM_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "image" / "declares-16384x16384.png");
  ASSERT_GT(png.size(), 33u);
  const fs::path dir = t.w() / "scan";
  fs::create_directory(dir);
  spit(dir / "upper.png", png);
  // Refused by the header's size, before decoding: decoding the few bytes of data would
  // fail with the decoder's own message instead, which names no size.
  ExpectExit(run(t, {"features", dir.string(), "--out", (t.w() / "f.csv").string()}, 30), 3,
             {(dir / "upper.png").string(), "16384x16384"});
}

// ---------------------------------------------------------------------------------------------
// Foreign data.h5 files: libhdf5 reads them in a child (io/contained.h), so its crash on a
// damaged file is that file's input error.

// The message of the InputError that read_contained throws, or "" when it returns.
std::string contained_error(const std::function<std::string()>& read) {
  try {
    portalsim::io::read_contained("f.h5", "libhdf5", read);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ContainedRead, ReturnsTheChildsBytesAndTurnsItsDeathIntoAnInputError) {
  std::string big(1 << 20, 'a');  // more than a pipe holds
  big[12345] = '\0';
  EXPECT_EQ(portalsim::io::read_contained("f.h5", "libhdf5", [&] { return big; }), big);
  EXPECT_EQ(contained_error([]() -> std::string { throw InputError("f.h5: dataset x is missing"); }),
            "f.h5: dataset x is missing");
  EXPECT_TRUE(has(contained_error([]() -> std::string {
                    std::raise(SIGSEGV);
                    return "";
                  }),
                  "f.h5: libhdf5 died reading it (signal 11"));
  EXPECT_TRUE(
      has(contained_error([]() -> std::string { ::_exit(0); }), "f.h5: libhdf5 died reading it (exit status 0)"));
  EXPECT_THROW(portalsim::io::read_contained("f.h5", "libhdf5", []() -> std::string { throw std::logic_error("bug"); }),
               std::runtime_error);
}

// Two data.h5 files that break libhdf5 1.10.8 (tests/fuzz/crashes/h5/): one makes it read
// past a heap buffer (H5HG_read), one makes it spin for ever. Both commands that read a
// user's data.h5 refuse them, naming them, with exit 3; the spin ends at the child's CPU
// limit (2 s), the run's limit below is a hang detector.
TEST(InputFiles, DataH5ThatBreaksLibhdf5IsRefusedNamingIt) {
  TempDir t;
  const fs::path crashes = fs::path(PORTALSIM_SOURCE_DIR) / "tests" / "fuzz" / "crashes" / "h5";
  const fs::path h5 = t.w() / "data.h5", spins = t.w() / "spins.h5";
  spit(h5, slurp(crashes / "h5hg-read-overflow.h5"));
  spit(spins, slurp(crashes / "libhdf5-spins.h5"));
  const fs::path out = t.w() / "out";
  ExpectExit(run(t, {"validate", "--sim", h5.string(), "--real", h5.string(), "--out", out.string()}), 3,
             {h5.string() + ": "});
  ExpectExit(run(t, {"calibrate", "--real", h5.string(), "--out", (out / "camera.toml").string()}), 3,
             {h5.string() + ": "});
  ExpectExit(run(t, {"validate", "--sim", spins.string(), "--real", spins.string(), "--out", out.string()}, 300), 3,
             {spins.string() + ": libhdf5 died reading it (signal 24"});
  EXPECT_FALSE(fs::exists(out));
}

// ---------------------------------------------------------------------------------------------
// Exit codes: usage 2, bad input file 3, output problem 4.

TEST(ExitCodes, UsageInputAndOutputErrorsAreTold) {
  TempDir t;
  const fs::path out = t.w() / "out";
  ExpectExit(run(t, {"generate", "--no-such-flag", "--out", out.string()}), 2, {"--no-such-flag"});
  ExpectExit(run(t, {"generate", "--count", "zero", "--out", out.string()}), 2, {"--count"});
  ExpectExit(run(t, {"generate", "--count", "5", "--seed", "1\x01", "--out", out.string()}), 2,
             {"--seed", "control character 0x01"});
  ExpectExit(run(t, {"simulate", "gun", "--rule", "gun\xFF", "--out", out.string()}), 2, {"--rule", "invalid UTF-8"});
  ExpectExit(run(t, {"generate", "--spec", (t.w() / "missing.toml").string(), "--out", out.string()}), 3,
             {"missing.toml"});
  // An unknown object: on the command line a usage error (2), in a file bad input (3) (issue 36).
  ExpectExit(run(t, {"simulate", "none", "nope", "--backend", "reference", "--out", out.string()}), 2,
             {"objects: region 2: unknown object \"nope\""});
  ExpectExit(run(t, {"generate", "--count", "5", "--pool", "gun,nope", "--quiet", "--backend", "reference", "--out",
                     out.string()}),
             2, {"--pool", "unknown object \"nope\""});
  spit(t.w() / "pool.toml", "count = 5\npool = [\"gun\", \"nope\"]\n");
  ExpectExit(run(t, {"generate", "--spec", (t.w() / "pool.toml").string(), "--quiet", "--backend", "reference", "--out",
                     out.string()}),
             3, {"pool.toml", "unknown object \"nope\""});
  spit(t.w() / "afile", "keep me\n");
  ExpectExit(run(t, {"generate", "--count", "5", "--quiet", "--out", (t.w() / "afile").string()}), 4, {"afile"});
  EXPECT_EQ(slurp(t.w() / "afile"), "keep me\n");
  EXPECT_FALSE(fs::exists(out));
}

// ---------------------------------------------------------------------------------------------
// Output folders.

TEST(OutputFolder, BusyFolderIsRefusedNamingTheHoldersPid) {
  TempDir t;
  const fs::path out = t.w() / "busy";
  fs::create_directories(out / ".portalsim");
  const int fd = ::open((out / ".portalsim" / "lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const std::string pid = std::to_string(::getpid());
  ASSERT_EQ(::write(fd, pid.data(), pid.size()), static_cast<ssize_t>(pid.size()));
  for (const Args& extra : {Args{}, Args{"--resume"}}) {
    Args a{"generate", "--count", "5", "--quiet", "--backend", "reference", "--out", out.string()};
    a.insert(a.end(), extra.begin(), extra.end());
    ExpectExit(run(t, a), 4, {out.string(), "PID " + pid});
  }
  ExpectExit(run(t, {"simulate", "gun", "--backend", "reference", "--out", out.string()}), 4, {"PID " + pid});
  EXPECT_EQ(fs::directory_iterator(out) == fs::directory_iterator(), false);
  EXPECT_FALSE(fs::exists(out / "features.arff.partial")) << "nothing written while another run holds it";
  ::close(fd);
  ExpectExit(run(t, {"generate", "--count", "5", "--quiet", "--backend", "reference", "--out", out.string()}), 0, {});
}

TEST(OutputFolder, RunStoppedBeforeItsFirstCheckpointCanBeResumedOrRerun) {
  TempDir t;
  // What a run killed between writing its marker and its first checkpoint leaves.
  for (const Args& extra : {Args{}, Args{"--resume"}}) {
    const fs::path out = t.w() / ("early" + std::to_string(extra.size()));
    fs::create_directories(out / ".portalsim");
    spit(out / ".portalsim" / "started", "{}\n");
    spit(out / "scenarios.csv.partial", "index,sub");
    Args a{"generate", "--count", "5", "--quiet", "--backend", "reference", "--out", out.string()};
    a.insert(a.end(), extra.begin(), extra.end());
    ExpectExit(run(t, a), 0, {});
    EXPECT_TRUE(fs::exists(out / "manifest.json"));
    EXPECT_FALSE(fs::exists(out / "scenarios.csv.partial"));
  }
}

TEST(OutputFolder, ResumingAFinishedRunWithOtherParametersNamesEveryDifference) {
  TempDir t;
  const fs::path out = t.w() / "done";
  const Args base{"generate", "--count",   "5",         "--seed", "1",
                  "--quiet",  "--backend", "reference", "--out",  out.string()};
  ExpectExit(run(t, base), 0, {});
  const std::string manifest = slurp(out / "manifest.json");
  Args other = base;
  other[2] = "6";
  other[4] = "2";
  other.push_back("--resume");
  ExpectExit(run(t, other), 2, {"--resume", "spec.count: 5 in the folder, 6 now", "spec.seed: 1 in the folder, 2 now"});
  EXPECT_EQ(slurp(out / "manifest.json"), manifest);
  Args same = base;
  same.push_back("--resume");
  ExpectExit(run(t, same), 0, {});
}

TEST(OutputFolder, AnErrorNeverDeletesWhatTheUserMade) {
  TempDir t;
  const fs::path link = t.w() / "link";
  fs::create_symlink(t.w() / "nowhere", link);
  for (const Args& cmd : {Args{"generate", "--count", "5", "--quiet"}, Args{"simulate", "gun"}}) {
    Args a = cmd;
    a.insert(a.end(), {"--backend", "reference", "--out", link.string()});
    ExpectExit(run(t, a), 4, {link.string(), "symlink"});
    EXPECT_TRUE(fs::is_symlink(link)) << "the dangling symlink must be kept";
  }
  // simulate follows generate's rules: a folder holding the user's files is refused.
  const fs::path mine = t.w() / "mine";
  fs::create_directory(mine);
  spit(mine / "notes.txt", "keep\n");
  ExpectExit(run(t, {"simulate", "gun", "--backend", "reference", "--out", mine.string()}), 4,
             {mine.string(), "not empty"});
  EXPECT_EQ(slurp(mine / "notes.txt"), "keep\n");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(mine)) names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"notes.txt"});
  // A simulate that succeeds leaves no state folder behind.
  const fs::path fresh = t.w() / "fresh";
  ExpectExit(run(t, {"simulate", "gun", "--backend", "reference", "--out", fresh.string()}), 0, {});
  EXPECT_FALSE(fs::exists(fresh / ".portalsim"));
}

}  // namespace

namespace {

// ---------------------------------------------------------------------------------------------
// The OpenCL environment: what is missing is named, and the way around it.

TEST(Environment, NoOpenClPlatformSaysSoAndNamesTheReferenceBackend) {
  TempDir t;
  const Result r = portalsim::test::finish(portalsim::test::start_program(
      t.cap(), "/usr/bin/env",
      {"OCL_ICD_VENDORS=/nonexistent", portalsim::test::kBinary, "simulate", "gun", "--out", (t.w() / "o").string()}));
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5) << "5: the OpenCL environment";
  EXPECT_TRUE(has(r.err, "no OpenCL platform found")) << "not clGetPlatformIDs";
  EXPECT_TRUE(has(r.err, "--backend reference"));
  EXPECT_FALSE(fs::exists(t.w() / "o"));
}

TEST(Environment, WithoutOpenClTheReferenceBackendStillRuns) {
  TempDir t;
  const Result r = portalsim::test::finish(
      portalsim::test::start_program(t.cap(), "/usr/bin/env",
                                     {"OCL_ICD_VENDORS=/nonexistent", portalsim::test::kBinary, "simulate", "gun",
                                      "--backend", "reference", "--out", (t.w() / "o").string()}));
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 0);
  EXPECT_TRUE(fs::exists(t.w() / "o" / "upper.png"));
}

TEST(Environment, AnUnknownDeviceIsAUsageError) {
  TempDir t;
  const Result r = portalsim::test::finish(portalsim::test::start_program(
      t.cap(), portalsim::test::kBinary,
      {"simulate", "gun", "--device", "no-such-device", "--out", (t.w() / "o").string()}));
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 2);
  EXPECT_TRUE(has(r.err, "--device: no OpenCL device matches"));
  EXPECT_FALSE(fs::exists(t.w() / "o"));
}

TEST(Environment, ReadOnlyPoclCacheIsNamed) {
  TempDir t;
  const fs::path cache = t.w() / "cache";
  const std::string cmd = "POCL_CACHE_DIR=" + portalsim::test::quoted(cache.string()) + " " + portalsim::test::kBinary +
                          " simulate gun --out " + portalsim::test::quoted((t.w() / "o").string());
  const Result r = portalsim::test::run_on_tmpfs(t.cap(), cache, "1m", true, cmd);
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5) << "5: the OpenCL environment";
  EXPECT_TRUE(has(r.err, cache.string())) << "the message must name the cache folder";
  EXPECT_TRUE(has(r.err, "writable"));
}

// PoCL's cache folder missing on a read-only file system: PoCL then offers no platform, and
// the message must name the cache and what to set, not ask to install PoCL (issue 36).
TEST(Environment, MissingPoclCacheOnAReadOnlyFileSystemIsNamed) {
  TempDir t;
  const fs::path mount = t.w() / "ro", cache = mount / "pocl";
  const std::string cmd = "POCL_CACHE_DIR=" + portalsim::test::quoted(cache.string()) + " " + portalsim::test::kBinary +
                          " simulate gun --out " + portalsim::test::quoted((t.w() / "o").string());
  const Result r = portalsim::test::run_on_tmpfs(t.cap(), mount, "1m", true, cmd);
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5) << "5: the OpenCL environment";
  EXPECT_TRUE(has(r.err, "PoCL's kernel cache, " + cache.string() + ", is missing and cannot be made"));
  EXPECT_TRUE(has(r.err, "POCL_CACHE_DIR, or XDG_CACHE_HOME, must name a writable folder"));
  EXPECT_FALSE(has(r.err, "is pocl-opencl-icd installed")) << "PoCL is installed: its cache is what failed";
  EXPECT_FALSE(fs::exists(t.w() / "o"));
}

}  // namespace
}  // namespace portalsim::test
