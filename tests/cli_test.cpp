// The command line as a user meets it: every test runs the real `portalsim` binary in its own
// temporary folder, reads its exit status, stdout and stderr, and looks at what it left on disk.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "assets/image_io.h"
#include "base/error.h"
#include "run_binary.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

// Metal detector outputs the thesis prints for its command-line examples (subject 1).
constexpr const char* kGunMetal = "193,112,75,2,1,1,96,200,200,190,196,53,53,94,64,82,53,200,200";
constexpr const char* kPipeMetal = "197,131,108,88,95,106,192,200,200,197,199,54,54,75,44,84,137,200,200";
constexpr const char* kMobileCdMetal = "200,183,165,136,137,142,193,200,200,198,199,185,185,195,176,175,190,200,200";
constexpr const char* kEmptyMetal = "200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200";

using Args = std::vector<std::string>;

Running start(const TempDir& t, const Args& args) { return portalsim::test::start(t.cap(), args); }

Result run(const TempDir& t, const Args& args) { return finish(start(t, args)); }

Args simulate(const Args& objects_and_options, const fs::path& out) {
  return with_out("simulate", objects_and_options, out);
}

struct ImageShape {
  bool ok = false;
  int width = 0, height = 0, channels = 0;
  std::string format;
};

// The file's format from its signature (PNG: 89 'PNG', JPEG: FF D8 FF), and its size and
// channels as portalsim's reader (OpenImageIO) decodes them.
ImageShape shape_of(const fs::path& p) {
  ImageShape s;
  std::ifstream f(p, std::ios::binary);
  std::string magic(4, '\0');
  if (!f.read(magic.data(), 4)) return s;
  if (magic == "\x89PNG") s.format = "png";
  if (magic.compare(0, 3, "\xFF\xD8\xFF") == 0) s.format = "jpeg";
  try {
    const portalsim::Image img = portalsim::read_image(p.string(), "test");
    s.width = img.width;
    s.height = img.height;
    s.channels = img.channels;
    s.ok = true;
  } catch (const portalsim::InputError&) {
  }
  return s;
}

const auto& ExpectSuccess = expect_success;

// Runs every case at once; each must be rejected cleanly with a message naming its needles.
void ExpectAllRejected(const TempDir& t, const std::vector<Rejection>& cases) {
  expect_all_rejected(t, "simulate", cases);
}

void ExpectAllRejected(const std::vector<Rejection>& cases) {
  TempDir t;
  ExpectAllRejected(t, cases);
}

void ExpectRejected(const TempDir& t, const Args& args, const std::vector<std::string>& needles,
                    bool also_existing = false) {
  ExpectAllRejected(t, {Rejection{args, needles, also_existing}});
}

void ExpectRejected(const Args& args, const std::vector<std::string>& needles, bool also_existing = false) {
  TempDir t;
  ExpectRejected(t, args, needles, also_existing);
}

std::string default_catalogue_text() { return slurp(fs::path(PORTALSIM_SOURCE_DIR) / "scenarios" / "catalogue.toml"); }

// Writes an edited copy of the default catalogue into the workspace and returns its path.
fs::path write_catalogue(const TempDir& t, const std::string& text, const std::string& name = "catalogue.toml") {
  const fs::path p = t.w() / name;
  spit(p, text);
  return p;
}

std::string at_line(const fs::path& file, int line) { return file.string() + ":" + std::to_string(line) + ":"; }

// Truncated PNG: the first 40 bytes of a real one (signature and part of the header chunk).
std::string truncated_png(const TempDir& t) {
  const fs::path dir = t.w() / "png-source";
  const Result r = run(t, simulate({}, dir));
  EXPECT_EQ(r.status, 0) << describe(r);
  return slurp(dir / "upper.png").substr(0, 40);
}

// ---------------------------------------------------------------------------------------------
// 1. The happy path.

TEST(CliSimulate, GunWritesExactlyTheSixFiles) {
  TempDir t;
  const fs::path out = t.w() / "out";
  const Result r = run(t, simulate({"none", "none", "none", "gun"}, out));
  ExpectSuccess(r);
  EXPECT_EQ(names_in(out),
            (std::vector<std::string>{"features.csv", "ir.png", "lower.png", "metal.txt", "threat.txt", "upper.png"}));
  EXPECT_EQ(names_in(t.w()), (std::vector<std::string>{"out"})) << "nothing may be left beside the output folder";
  EXPECT_EQ(slurp(out / "metal.txt"), std::string(kGunMetal) + "\n");
  EXPECT_EQ(slurp(out / "threat.txt"), "no\n");
  EXPECT_TRUE(has(r.out, kGunMetal)) << describe(r);

  for (const char* view : {"upper.png", "lower.png"}) {
    const ImageShape s = shape_of(out / view);
    ASSERT_TRUE(s.ok) << view << " is not a readable image";
    EXPECT_EQ(s.format, "png") << view;
    EXPECT_EQ(s.width, 200) << view;
    EXPECT_EQ(s.height, 200) << view;
    EXPECT_EQ(s.channels, 1) << view;
  }
  const ImageShape ir = shape_of(out / "ir.png");
  ASSERT_TRUE(ir.ok) << "ir.png is not a readable image";
  EXPECT_EQ(ir.format, "png");
  EXPECT_EQ(ir.width, 100);
  EXPECT_EQ(ir.height, 200);
  EXPECT_EQ(ir.channels, 3);
}

// --timing names the path each view took, as the backend chose it (OpenCLPaths.* hold the
// choices themselves); generate names the features path of a features-only run.
TEST(CliSimulate, TimingNamesThePathEachViewTook) {
  TempDir t;
  const Result r = run(t, simulate({"--model", "physics", "--timing", "none", "none", "none", "gun"}, t.w() / "out"));
  ExpectSuccess(r);
  EXPECT_TRUE(has(r.out,
                  "\npaths: upper: physics_raw (fixed window), lower: physics_raw (fixed window), "
                  "ir: ir_fused (surface, noise and display fused), features: pooled from the rendered views\n"))
      << describe(r);
  const Result g = run(t, {"generate", "--count", "8", "--timing", "--out", (t.w() / "set").string()});
  ExpectSuccess(g);
  EXPECT_TRUE(has(g.out, "\npaths: features: thesis_sparse_features (pattern noise)\n")) << describe(g);
}

TEST(CliSimulate, FeaturesCsvHasHeaderAndOneMatchingRow) {
  TempDir t;
  const fs::path out = t.w() / "out";
  ExpectSuccess(run(t, simulate({"none", "none", "none", "gun"}, out)));
  const std::string csv = slurp(out / "features.csv");
  ASSERT_FALSE(csv.empty());
  ASSERT_EQ(csv.back(), '\n') << "features.csv must end with a newline";
  const std::vector<std::string> lines = split(csv.substr(0, csv.size() - 1), '\n');
  ASSERT_EQ(lines.size(), 2u) << "a header line and one data row";
  const std::vector<std::string> header = split(lines[0], ','), row = split(lines[1], ',');
  EXPECT_EQ(header.size(), row.size());
  // 20x20 blocks of 10 pixels per MMW view, 13 region features, 19 zones, the class.
  EXPECT_EQ(header.size(), 2u * 20 * 20 + 13 + 19 + 1);
  EXPECT_EQ(header.back(), "class");
  EXPECT_EQ(row.back(), "negative");
  ASSERT_GE(row.size(), 20u);
  std::string metal;
  for (size_t i = row.size() - 20; i + 1 < row.size(); ++i) metal += (metal.empty() ? "" : ",") + row[i];
  EXPECT_EQ(metal, kGunMetal) << "the 19 zone columns before the class are the metal detector's output";
  for (const std::string& f : row) EXPECT_FALSE(f.empty()) << "no empty fields";
}

TEST(CliSimulate, ThreatYesAndBlockSize) {
  TempDir t;
  const fs::path out = t.w() / "out";
  const Result r = run(t, simulate({"none", "none", "none", "gun", "--threat", "yes", "--block", "20"}, out));
  ExpectSuccess(r);
  EXPECT_EQ(slurp(out / "threat.txt"), "yes\n");
  EXPECT_EQ(slurp(out / "metal.txt"), std::string(kGunMetal) + "\n");
  const std::vector<std::string> lines = split(slurp(out / "features.csv"), '\n');
  ASSERT_EQ(lines.size(), 3u);  // header, row, the empty string after the final newline
  EXPECT_EQ(lines[2], "");
  const std::vector<std::string> header = split(lines[0], ','), row = split(lines[1], ',');
  EXPECT_EQ(header.size(), row.size());
  EXPECT_EQ(header.size(), 2u * 10 * 10 + 13 + 19 + 1) << "--block 20 gives 10x10 blocks per view";
  EXPECT_EQ(row.back(), "positive");
  EXPECT_TRUE(has(r.out, "threat yes")) << describe(r);
}

TEST(CliSimulate, JpgImageFormat) {
  TempDir t;
  const fs::path out = t.w() / "out";
  ExpectSuccess(run(t, simulate({"none", "none", "none", "gun", "--image-format", "jpg"}, out)));
  EXPECT_EQ(names_in(out),
            (std::vector<std::string>{"features.csv", "ir.jpg", "lower.jpg", "metal.txt", "threat.txt", "upper.jpg"}));
  for (const char* view : {"upper.jpg", "lower.jpg"}) {
    const ImageShape s = shape_of(out / view);
    ASSERT_TRUE(s.ok) << view;
    EXPECT_EQ(s.format, "jpeg") << view;
    EXPECT_EQ(s.width, 200) << view;
    EXPECT_EQ(s.height, 200) << view;
    EXPECT_EQ(s.channels, 1) << view;
  }
  const ImageShape ir = shape_of(out / "ir.jpg");
  ASSERT_TRUE(ir.ok);
  EXPECT_EQ(ir.format, "jpeg");
  EXPECT_EQ(ir.width, 100);
  EXPECT_EQ(ir.height, 200);
  EXPECT_EQ(ir.channels, 3);
  EXPECT_EQ(slurp(out / "metal.txt"), std::string(kGunMetal) + "\n");
}

// ---------------------------------------------------------------------------------------------
// 2. The thesis's examples, on both backends.

TEST(CliThesis, ExamplesOnBothBackends) {
  TempDir t;
  struct Case {
    Args objects;
    const char* metal;
  };
  const std::vector<Case> cases{{{"none", "none", "none", "gun"}, kGunMetal},
                                {{"none", "none", "iron-pipe"}, kPipeMetal},
                                {{"none", "none", "mobile", "none", "none", "none", "cd"}, kMobileCdMetal}};
  std::vector<Args> commands;
  for (size_t i = 0; i < cases.size(); ++i) {
    commands.push_back(simulate(cases[i].objects, t.w() / (std::string("opencl") + std::to_string(i))));
    Args ref = cases[i].objects;
    ref.insert(ref.end(), {"--backend", "reference"});
    commands.push_back(simulate(ref, t.w() / (std::string("reference") + std::to_string(i))));
  }
  const std::vector<Result> r = run_all(t, commands);
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(r[2 * i].command);
    ExpectSuccess(r[2 * i]);
    ExpectSuccess(r[2 * i + 1]);
    const std::string ocl = slurp(t.w() / (std::string("opencl") + std::to_string(i)) / "metal.txt");
    const std::string ref = slurp(t.w() / (std::string("reference") + std::to_string(i)) / "metal.txt");
    EXPECT_EQ(ocl, std::string(cases[i].metal) + "\n") << "opencl backend";
    EXPECT_EQ(ref, std::string(cases[i].metal) + "\n") << "reference backend";
    EXPECT_EQ(ocl, ref);
  }
}

// ---------------------------------------------------------------------------------------------
// 3. Object names.

TEST(CliNames, CaseAndAliasesAreAccepted) {
  TempDir t;
  const std::vector<Args> objects{{"none", "none", "none", "Gun"},
                                  {"none", "none", "none", "GUN"},
                                  {"none", "none", "metal-barrel"},
                                  {"none", "none", "Mobile", "none", "none", "none", "CD"},
                                  {"Rod"},
                                  {"iron-rod"}};
  std::vector<Args> commands;
  for (size_t i = 0; i < objects.size(); ++i) commands.push_back(simulate(objects[i], t.w() / std::to_string(i)));
  const std::vector<Result> r = run_all(t, commands);
  for (const Result& x : r) ExpectSuccess(x);
  const auto metal = [&](int i) { return slurp(t.w() / std::to_string(i) / "metal.txt"); };
  EXPECT_EQ(metal(0), std::string(kGunMetal) + "\n") << "Gun";
  EXPECT_EQ(metal(1), std::string(kGunMetal) + "\n") << "GUN";
  EXPECT_EQ(metal(2), std::string(kPipeMetal) + "\n") << "metal-barrel is iron-pipe";
  EXPECT_EQ(metal(3), std::string(kMobileCdMetal) + "\n") << "Mobile and CD";
  EXPECT_EQ(metal(4), metal(5)) << "Rod is iron-rod";
  EXPECT_EQ(slurp(t.w() / "4" / "upper.png"), slurp(t.w() / "5" / "upper.png")) << "Rod is iron-rod";
}

TEST(CliNames, Orientations) {
  TempDir t;
  const std::vector<Args> objects{{"gun"},   {"gun:h"},      {"gun:horizontal"},   {"gun:v"},
                                  {"Rod:V"}, {"iron-rod:v"}, {"iron-rod:VERTICAL"}};
  std::vector<Args> commands;
  for (size_t i = 0; i < objects.size(); ++i) commands.push_back(simulate(objects[i], t.w() / std::to_string(i)));
  const std::vector<Result> r = run_all(t, commands);
  for (const Result& x : r) ExpectSuccess(x);
  const auto upper = [&](int i) { return slurp(t.w() / std::to_string(i) / "upper.png"); };
  EXPECT_FALSE(upper(0).empty());
  EXPECT_EQ(upper(0), upper(1)) << "gun is drawn horizontally by default";
  EXPECT_EQ(upper(1), upper(2)) << "gun:horizontal is gun:h";
  EXPECT_NE(upper(0), upper(3)) << "gun:v must be drawn differently from gun:h";
  EXPECT_EQ(upper(4), upper(5)) << "Rod:V is iron-rod:v";
  EXPECT_EQ(upper(5), upper(6)) << "iron-rod:VERTICAL is iron-rod:v";
}

TEST(CliNames, FewerThanThirteenObjectsFillWithNone) {
  TempDir t;
  const std::vector<Result> r = run_all(
      t,
      {simulate({"none", "none", "none", "gun"}, t.w() / "short"),
       simulate({"none", "none", "none", "gun", "none", "none", "none", "none", "none", "none", "none", "none", "none"},
                t.w() / "full")});
  ExpectSuccess(r[0]);
  ExpectSuccess(r[1]);
  const std::vector<std::string> names = names_in(t.w() / "short");
  ASSERT_EQ(names, names_in(t.w() / "full"));
  ASSERT_EQ(names.size(), 6u);
  for (const std::string& n : names)
    EXPECT_EQ(slurp(t.w() / "short" / n), slurp(t.w() / "full" / n)) << n << " differs";
}

TEST(CliNames, NoObjectsAtAll) {
  TempDir t;
  const fs::path out = t.w() / "out";
  ExpectSuccess(run(t, simulate({}, out)));
  EXPECT_EQ(slurp(out / "metal.txt"), std::string(kEmptyMetal) + "\n");
  EXPECT_EQ(slurp(out / "threat.txt"), "no\n");
  EXPECT_EQ(names_in(out).size(), 6u);
}

// ---------------------------------------------------------------------------------------------
// 4. Labels.

TEST(CliLabels, RuleNamingAnObjectPresent) {
  TempDir t;
  const fs::path out = t.w() / "out";
  const Result r = run(t, simulate({"gun", "--rule", "gun"}, out));
  ExpectSuccess(r);
  EXPECT_EQ(slurp(out / "threat.txt"), "yes\n");
  EXPECT_TRUE(has(slurp(out / "features.csv"), ",positive\n"));
  EXPECT_TRUE(has(r.out, "threat yes")) << describe(r);
}

TEST(CliLabels, RuleAllOf) {
  TempDir t;
  const std::vector<Result> r =
      run_all(t, {simulate({"rod", "--rule", "iron-rod&metal-plate"}, t.w() / "rod"),
                  simulate({"rod", "plate", "--rule", "iron-rod&metal-plate"}, t.w() / "both"),
                  simulate({"rod", "--rule", "iron-rod&metal-plate", "--threat", "yes"}, t.w() / "conflict")});
  ExpectSuccess(r[0]);
  ExpectSuccess(r[1]);
  EXPECT_EQ(slurp(t.w() / "rod" / "threat.txt"), "no\n") << "only the rod: the rule does not hold";
  EXPECT_TRUE(has(slurp(t.w() / "rod" / "features.csv"), ",negative\n"));
  EXPECT_EQ(slurp(t.w() / "both" / "threat.txt"), "yes\n") << "rod and plate: the rule holds";
  EXPECT_TRUE(has(slurp(t.w() / "both" / "features.csv"), ",positive\n"));
  expect_clean_failure(r[2], t.w() / "conflict", false, {"--rule", "--threat"});
}

TEST(CliLabels, RuleAndThreatTogetherAreRejected) {
  ExpectRejected({"gun", "--rule", "gun", "--threat", "no"}, {"--rule", "--threat"}, true);
}

TEST(CliLabels, RuleWithUnknownObjectIsRejected) {
  ExpectRejected({"gun", "--rule", "gun|flamethrower"}, {"--rule", "flamethrower"});
}

// ---------------------------------------------------------------------------------------------
// 5. Determinism.

TEST(CliDeterminism, SameSeedGivesByteIdenticalFiles) {
  TempDir t;
  const Args args{"gun",    "rod:v", "mobile",        "none", "plate",         "none", "cd",
                  "--seed", "12345", "--pixel-noise", "3",    "--metal-noise", "4"};
  const std::vector<Result> r = run_all(t, {simulate(args, t.w() / "a"), simulate(args, t.w() / "b")});
  ExpectSuccess(r[0]);
  ExpectSuccess(r[1]);
  const std::vector<std::string> names = names_in(t.w() / "a");
  ASSERT_EQ(names.size(), 6u);
  ASSERT_EQ(names, names_in(t.w() / "b"));
  for (const std::string& n : names) {
    const std::string a = slurp(t.w() / "a" / n);
    EXPECT_FALSE(a.empty()) << n;
    EXPECT_EQ(a, slurp(t.w() / "b" / n)) << n << " differs between two runs with the same seed";
  }
}

TEST(CliDeterminism, DifferentSeedsChangeTheMmwImages) {
  TempDir t;
  // Only the choice of noise pattern (one of 5) and its placement depend on the seed here, so two
  // seeds may coincide; among six seeds at least one must give different MMW images.
  const Args objects{"gun", "rod", "mobile", "none", "none", "none", "none", "none", "gun:v"};
  std::vector<Args> commands;
  for (int seed = 1; seed <= 6; ++seed) {
    Args a = objects;
    a.insert(a.end(), {"--seed", std::to_string(seed)});
    commands.push_back(simulate(a, t.w() / std::to_string(seed)));
  }
  const std::vector<Result> r = run_all(t, commands);
  for (const Result& x : r) ExpectSuccess(x);
  const auto mmw = [&](int seed) {
    return slurp(t.w() / std::to_string(seed) / "upper.png") + slurp(t.w() / std::to_string(seed) / "lower.png");
  };
  int differing = 0;
  for (int seed = 2; seed <= 6; ++seed) differing += mmw(seed) != mmw(1);
  EXPECT_GT(differing, 0) << "seeds 1 to 6 all gave the same upper.png and lower.png";
}

TEST(CliDeterminism, PixelNoiseDependsOnSeed) {
  TempDir t;
  const std::vector<Result> r = run_all(t, {simulate({"--pixel-noise", "5", "--seed", "1"}, t.w() / "s1"),
                                            simulate({"--pixel-noise", "5", "--seed", "2"}, t.w() / "s2"),
                                            simulate({"--pixel-noise", "5", "--seed", "1"}, t.w() / "s1again")});
  for (const Result& x : r) ExpectSuccess(x);
  EXPECT_NE(slurp(t.w() / "s1" / "upper.png"), slurp(t.w() / "s2" / "upper.png"));
  EXPECT_NE(slurp(t.w() / "s1" / "lower.png"), slurp(t.w() / "s2" / "lower.png"));
  EXPECT_EQ(slurp(t.w() / "s1" / "upper.png"), slurp(t.w() / "s1again" / "upper.png"));
}

// ---------------------------------------------------------------------------------------------
// 6. Bad input: objects and options.

TEST(CliBadInput, UnknownObject) { ExpectRejected({"none", "flamethrower"}, {"flamethrower", "region 2"}, true); }

TEST(CliBadInput, UnknownOrientation) { ExpectRejected({"gun:x"}, {"region 1", "gun", "\"x\""}); }

TEST(CliBadInput, OrientationOnSingleDrawingObject) {
  ExpectRejected({"none", "none", "disk:v"}, {"region 3", "compact-disk", "\"v\""});
}

TEST(CliBadInput, OrientationOnEmptyRegion) { ExpectRejected({"none:v"}, {"region 1", "none:v"}); }

TEST(CliBadInput, MoreThanThirteenObjects) {
  ExpectAllRejected({{Args(14, "none"), {"14", "13"}}, {Args(14, "gun"), {"14", "13"}}});
}

TEST(CliBadInput, SubjectOutOfRange) {
  ExpectAllRejected({{{"gun", "--subject", "0"}, {"--subject", "0"}}, {{"gun", "--subject", "6"}, {"--subject", "6"}}});
}

TEST(CliBadInput, SubjectNotANumber) { ExpectRejected({"gun", "--subject", "abc"}, {"--subject", "abc"}, true); }

TEST(CliBadInput, MalformedSeeds) {
  std::vector<Rejection> cases;
  for (const char* seed : {"abc", "-1", "18446744073709551616", "1.5", "0x", "0x10000000000000000", ""})
    cases.push_back({{"gun", "--seed", seed}, {"--seed", std::string("\"") + seed + "\""}, cases.empty()});
  ExpectAllRejected(cases);
}

TEST(CliBadInput, LargestSeedAndHexSeedAreAccepted) {
  TempDir t;
  const std::vector<Result> r = run_all(t, {simulate({"gun", "rod", "--seed", "18446744073709551615"}, t.w() / "max"),
                                            simulate({"gun", "rod", "--seed", "0xFFFFFFFFFFFFFFFF"}, t.w() / "maxhex"),
                                            simulate({"gun", "rod", "--seed", "0x10"}, t.w() / "hex"),
                                            simulate({"gun", "rod", "--seed", "16"}, t.w() / "dec")});
  for (const Result& x : r) ExpectSuccess(x);
  for (const auto& [a, b] : {std::pair{"max", "maxhex"}, std::pair{"hex", "dec"}}) {
    const std::vector<std::string> names = names_in(t.w() / a);
    ASSERT_EQ(names.size(), 6u) << a;
    ASSERT_EQ(names, names_in(t.w() / b));
    for (const std::string& n : names)
      EXPECT_EQ(slurp(t.w() / a / n), slurp(t.w() / b / n)) << n << ": " << a << " and " << b << " are one seed";
  }
}

TEST(CliBadInput, BlockSize) {
  ExpectAllRejected(
      {{{"gun", "--block", "0"}, {"--block", "0"}, true}, {{"gun", "--block", "100000"}, {"--block", "100000"}}});
}

TEST(CliBadInput, PixelNoise) {
  ExpectAllRejected(
      {{{"gun", "--pixel-noise", "-1"}, {"--pixel-noise"}}, {{"gun", "--pixel-noise", "nan"}, {"--pixel-noise"}}});
}

TEST(CliBadInput, MetalNoise) { ExpectRejected({"gun", "--metal-noise", "500"}, {"--metal-noise"}); }

TEST(CliBadInput, ImageFormat) { ExpectRejected({"gun", "--image-format", "bmp"}, {"--image-format", "bmp"}); }

TEST(CliBadInput, Backend) { ExpectRejected({"gun", "--backend", "cuda"}, {"--backend", "cuda"}); }

TEST(CliBadInput, EmptyOutNamesTheOption) {
  TempDir t;
  const Result r = run(t, {"simulate", "gun", "--out", ""});
  SCOPED_TRACE(describe(r));
  EXPECT_FALSE(r.signaled);
  EXPECT_TRUE(r.exited);
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(message_lines(r.err).size(), 1u);
  EXPECT_TRUE(has(r.err, "--out")) << "an empty output folder name must be reported as --out";
}

// ---------------------------------------------------------------------------------------------
// 6. Bad input: the output folder.

TEST(CliOutput, ParentIsARegularFile) {
  TempDir t;
  const fs::path file = t.w() / "afile";
  spit(file, "keep me\n");
  const fs::path out = file / "out";
  const Result r = run(t, simulate({"gun"}, out));
  expect_clean_failure(r, out, false, {out.string()});
  EXPECT_EQ(slurp(file), "keep me\n");
  EXPECT_EQ(names_in(t.w()), (std::vector<std::string>{"afile"}));
}

TEST(CliOutput, OutIsARegularFile) {
  TempDir t;
  const fs::path file = t.w() / "afile";
  spit(file, "keep me\n");
  const Result r = run(t, simulate({"gun"}, file));
  SCOPED_TRACE(describe(r));
  EXPECT_FALSE(r.signaled);
  EXPECT_TRUE(r.exited);
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(message_lines(r.err).size(), 1u);
  EXPECT_TRUE(has(r.err, file.string()));
  EXPECT_EQ(slurp(file), "keep me\n") << "the file must be left alone";
  EXPECT_EQ(names_in(t.w()), (std::vector<std::string>{"afile"}));
}

// Root ignores permissions, so the read-only and full-disk tests use a small tmpfs in a
// private mount namespace (unshare -m): read-only, or too small for the images.
// The script prints what the folder holds afterwards; the mount goes with the namespace.
struct TmpfsRun {
  Result r;
  std::vector<std::string> left;  // paths under the mount after the run
};

TmpfsRun run_on_tmpfs(const TempDir& t, const std::string& size, bool read_only, const std::string& prepare,
                      const Args& args) {
  const fs::path mnt = t.w() / "mnt";
  std::string cmd = quoted(portalsim::test::kBinary);
  for (const std::string& a : args) {
    cmd += ' ';  // appended apart: g++ 12 warns (-Wrestrict) on " " + std::string&&
    cmd += quoted(a);
  }
  const std::string listing = (t.cap() / "listing").string();
  const std::string script = (prepare.empty() ? "" : prepare + " && ") +
                             (read_only ? "mount -o remount,ro " + quoted(mnt.string()) + " && " : "") + cmd +
                             "; rc=$?; (cd " + quoted(mnt.string()) + " && find . -mindepth 1) > " + quoted(listing) +
                             "; exit $rc";
  TmpfsRun out;
  out.r = portalsim::test::run_on_tmpfs(t.cap(), mnt, size, false, script);
  std::istringstream in(slurp(listing));
  for (std::string line; std::getline(in, line);) out.left.push_back(line);
  return out;
}

TEST(CliOutput, ReadOnlyParent) {
  TempDir t;
  const fs::path out = t.w() / "mnt" / "out";
  const TmpfsRun x = run_on_tmpfs(t, "1m", true, "", simulate({"gun"}, out));
  expect_clean_failure(x.r, out, false, {out.string()});
  EXPECT_EQ(x.r.status, 4) << "an output problem exits 4";
  EXPECT_TRUE(x.left.empty()) << testing::PrintToString(x.left);
}

TEST(CliOutput, ReadOnlyOutFolder) {
  TempDir t;
  const fs::path out = t.w() / "mnt" / "out";
  const TmpfsRun x = run_on_tmpfs(t, "1m", true, "mkdir " + quoted(out.string()), simulate({"gun"}, out));
  expect_clean_failure(x.r, out, false, {out.string()});  // out lived on the tmpfs, gone now
  EXPECT_EQ(x.r.status, 4) << "an output problem exits 4";
  EXPECT_EQ(x.left, std::vector<std::string>{"./out"});
}

TEST(CliOutput, NoFoldersLeftWhenTheDiskFillsAfterCreatingThem) {
  // The disk (a 16 KiB tmpfs) fills while the images are written, after out/ and the folders
  // above it (a/, a/b/) were made: all of them must go, and the exit says output problem.
  TempDir t;
  const fs::path out = t.w() / "mnt" / "a" / "b" / "out";
  const TmpfsRun x = run_on_tmpfs(t, "16k", false, "", simulate({"gun"}, out));
  expect_clean_failure(x.r, out, false, {});
  EXPECT_EQ(x.r.status, 4) << "a full disk is an output problem\n" << describe(x.r);
  EXPECT_TRUE(x.left.empty()) << "left behind: " << testing::PrintToString(x.left);
}

// A disk already full (a file fills the 64 KiB tmpfs first): the first write that fails is
// the lock's PID in OUT/.portalsim/lock. Nothing of the run's may stay: not .portalsim/,
// not OUT/ when the run made it, and an OUT/ that was there stays as it was.
TEST(CliOutput, NothingLeftWhenTheDiskIsFullFromTheStart) {
  for (const bool out_exists : {false, true}) {
    SCOPED_TRACE(out_exists ? "out/ exists" : "out/ is made by the run");
    TempDir t;
    const fs::path mnt = t.w() / "mnt", out = mnt / "out";
    const std::string fill = "(dd if=/dev/zero of=" + quoted((mnt / "fill").string()) + " bs=4k 2>/dev/null; true)";
    const TmpfsRun x = run_on_tmpfs(
        t, "64k", false, out_exists ? "mkdir " + quoted(out.string()) + " && " + fill : fill, simulate({"gun"}, out));
    expect_clean_failure(x.r, out, false, {});
    EXPECT_EQ(x.r.status, 4) << "a full disk is an output problem\n" << describe(x.r);
    std::vector<std::string> left = x.left;
    std::sort(left.begin(), left.end());
    const std::vector<std::string> want =
        out_exists ? std::vector<std::string>{"./fill", "./out"} : std::vector<std::string>{"./fill"};
    EXPECT_EQ(left, want);
  }
}

TEST(CliOutput, FeaturesOnAFullDiskLeavesNoPartialFile) {
  TempDir t;
  const fs::path scans = t.w() / "scans";
  ASSERT_EQ(run(t, simulate({"gun"}, scans / "s1")).status, 0);
  const fs::path table = t.w() / "mnt" / "table.csv";
  // Block 1: one feature per pixel, a table far larger than the 64 KiB disk.
  const TmpfsRun x =
      run_on_tmpfs(t, "64k", false, "", {"features", scans.string(), "--block", "1", "--out", table.string()});
  SCOPED_TRACE(describe(x.r));
  EXPECT_TRUE(x.r.exited);
  EXPECT_EQ(x.r.status, 4);
  EXPECT_TRUE(has(x.r.err, table.string()));
  EXPECT_TRUE(x.left.empty()) << "left behind: " << testing::PrintToString(x.left);
}

// ---------------------------------------------------------------------------------------------
// 6. Bad input: the catalogue.

TEST(CliCatalogueFile, UnmodifiedCopyWorks) {
  TempDir t;
  const fs::path cat = write_catalogue(t, default_catalogue_text());
  const fs::path out = t.w() / "out";
  ExpectSuccess(run(t, simulate({"--catalogue", cat.string(), "none", "none", "none", "gun"}, out)));
  EXPECT_EQ(slurp(out / "metal.txt"), std::string(kGunMetal) + "\n");
}

TEST(CliCatalogueFile, NonexistentFile) {
  ExpectRejected({"--catalogue", "/nonexistent.toml", "gun"}, {"/nonexistent.toml", "catalogue"}, true);
}

// The default catalogue with `from` replaced by `to`, given to simulate: it must be rejected
// naming the file and the line of `to`, and `more`.
void ExpectEditRejected(const std::string& from, const std::string& to, std::vector<std::string> more,
                        bool also_existing = false) {
  TempDir t;
  const std::string text = replace_once(default_catalogue_text(), from, to);
  const fs::path cat = write_catalogue(t, text);
  more.insert(more.begin(), at_line(cat, line_of(text, to)));
  ExpectRejected(t, {"--catalogue", cat.string(), "gun"}, more, also_existing);
}

TEST(CliCatalogueFile, SyntaxError) { ExpectEditRejected("alpha = 0.9", "alpha = = 0.9", {}, true); }

TEST(CliCatalogueFile, RegionRectangleWithThreeValues) {
  ExpectEditRejected("upper = [117, 40, 34, 70]", "upper = [1, 2, 3]", {"regions[3].rects.upper", "3"});
}

TEST(CliCatalogueFile, RegionRectangleOutsideTheView) {
  ExpectEditRejected("upper = [117, 40, 34, 70]", "upper = [180, 40, 34, 70]", {"regions[3].rects.upper", "outside"});
}

TEST(CliCatalogueFile, AlphaNotANumber) { ExpectEditRejected("alpha = 0.9", "alpha = nan", {"images.alpha", "NaN"}); }

TEST(CliCatalogueFile, AlphaOutOfRange) { ExpectEditRejected("alpha = 0.9", "alpha = 1.5", {"images.alpha", "1.5"}); }

// The first subject's base zones in the default catalogue.
const char* const kZones19 =
    "base_zones = [200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200]";

TEST(CliCatalogueFile, BaseZonesWithEighteenValues) {
  const std::string zones18 =
      "base_zones = [200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200]";
  ExpectEditRejected(kZones19, zones18, {"subjects[1].base_zones", "18"});
}

TEST(CliCatalogueFile, BaseZoneValueAbove200) {
  const std::string bad =
      "base_zones = [200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 200, 201, 200]";
  ExpectEditRejected(kZones19, bad, {"subjects[1].base_zones", "201"});
}

TEST(CliCatalogueFile, UnknownMetalCategory) {
  ExpectEditRejected("metal = \"heavy\"", "metal = \"plutonium\"", {"objects[1].metal", "plutonium"});
}

TEST(CliCatalogueFile, DuplicateObjectName) {
  TempDir t;
  const std::string text = replace_once(default_catalogue_text(), "name = \"iron-handle\"", "name = \"gun\"");
  const fs::path cat = write_catalogue(t, text);
  // The duplicate's table: its [[objects]] header or its name line.
  const int name_line = line_of(text, "name = \"gun\"\naliases = [\"handle\"]");
  ASSERT_GT(name_line, 1);
  const Result r = run(t, simulate({"--catalogue", cat.string(), "gun"}, t.w() / "out"));
  expect_clean_failure(r, t.w() / "out", false, {cat.string() + ":", "objects[2]", "gun"});
  EXPECT_TRUE(has(r.err, at_line(cat, name_line)) || has(r.err, at_line(cat, name_line - 1)))
      << "the message must give the line of the duplicate entry (" << name_line << " or " << name_line - 1
      << "): " << r.err;
}

TEST(CliCatalogueFile, MissingMetalTable) {
  TempDir t;
  std::string text = default_catalogue_text();
  const size_t begin = text.find("[metal]"), end = text.find("# END metal table");
  ASSERT_NE(begin, std::string::npos);
  ASSERT_NE(end, std::string::npos);
  text.erase(begin, end - begin);
  const fs::path cat = write_catalogue(t, text);
  ExpectRejected(t, {"--catalogue", cat.string(), "gun"}, {cat.string() + ":", "metal", "missing"});
}

// `line` added after the object's `name_line` in the default catalogue, the image `file` in
// t's workspace: simulate must be rejected naming the catalogue's line, `field` and the image.
void ExpectImageRejected(const TempDir& t, const std::string& name_line, const std::string& line,
                         const std::string& field, const std::string& file) {
  const std::string text = replace_once(default_catalogue_text(), name_line + "\n", name_line + "\n" + line + "\n");
  const fs::path cat = write_catalogue(t, text);
  ExpectRejected(t, {"--catalogue", cat.string(), "gun"},
                 {at_line(cat, line_of(text, line)), field, (t.w() / file).string()}, true);
}

// The first object (gun) has two drawings; `mmw` names the image for every drawing it does
// not give an mmw_h / mmw_v for. A file that cannot be used must be reported, not ignored.
TEST(CliCatalogueImage, MissingImageOnFirstObject) {
  TempDir t;
  ExpectImageRejected(t, "name = \"gun\"", "mmw = \"missing.png\"", "objects[1].mmw", "missing.png");
}

TEST(CliCatalogueImage, TruncatedPngOnFirstObject) {
  TempDir t;
  spit(t.w() / "corrupt.png", truncated_png(t));
  ExpectImageRejected(t, "name = \"gun\"", "mmw = \"corrupt.png\"", "objects[1].mmw", "corrupt.png");
}

TEST(CliCatalogueImage, MissingVariantImage) {
  TempDir t;
  ExpectImageRejected(t, "name = \"gun\"", "mmw_h = \"missing.png\"", "objects[1].mmw_h", "missing.png");
}

TEST(CliCatalogueImage, GarbageImageOnSingleDrawingObject) {
  TempDir t;
  spit(t.w() / "corrupt.png", "this is not an image, only some garbage bytes \x01\x02\x03\xff\n");
  ExpectImageRejected(t, "name = \"iron-handle\"", "mmw = \"corrupt.png\"", "objects[2].mmw", "corrupt.png");
}

TEST(CliCatalogueImage, TruncatedPngOnSingleDrawingObject) {
  TempDir t;
  spit(t.w() / "corrupt.png", truncated_png(t));
  ExpectImageRejected(t, "name = \"iron-handle\"", "mmw = \"corrupt.png\"", "objects[2].mmw", "corrupt.png");
}

// ---------------------------------------------------------------------------------------------
// 7. portalsim catalogue.

// The non-empty lines after the line starting with `heading`, up to the next empty line.
std::vector<std::string> section(const std::string& text, const std::string& heading) {
  std::vector<std::string> out;
  bool in = false;
  for (const std::string& l : split(text, '\n')) {
    if (!in) {
      in = l.rfind(heading, 0) == 0;
      continue;
    }
    if (l.empty()) break;
    out.push_back(l);
  }
  return out;
}

TEST(CliCatalogueCmd, ListsObjectsAndRegions) {
  TempDir t;
  const Result r = run(t, {"catalogue"});
  ExpectSuccess(r);
  SCOPED_TRACE(describe(r));
  const std::vector<std::string> regions = section(r.out, "regions:");
  const std::vector<std::string> objects = section(r.out, "objects");
  const std::vector<std::string> subjects = section(r.out, "subjects:");
  EXPECT_EQ(regions.size(), 13u);
  EXPECT_EQ(objects.size(), 31u);
  EXPECT_EQ(subjects.size(), 5u);
  // "  * gun ..." for the default pool's objects, "    knife-chef ..." for the rest.
  std::vector<std::string> in_default;
  for (const std::string& l : objects)
    if (l.size() > 2 && l[2] == '*') in_default.push_back(split(l.substr(4), ' ')[0]);
  EXPECT_EQ(in_default, (std::vector<std::string>{"gun", "iron-handle", "iron-rod", "compact-disk", "metal-strip",
                                                  "metal-plate", "pendant", "iron-pipe", "belt-buckle", "ceramic-plate",
                                                  "cement-tile", "mobile-phone"}));
  EXPECT_TRUE(std::any_of(objects.begin(), objects.end(), [](const std::string& l) {
    return l.rfind("    knife-chef ", 0) == 0 && has(l, " large   threat  knife ");
  })) << "knife-chef's line names its metal, class and family";
  EXPECT_TRUE(has(r.out, "left-chest"));
  EXPECT_TRUE(has(r.out, "camera views: upper mmw 200x200; lower mmw 200x200; ir ir 100x200; alpha 0.9"));
  EXPECT_TRUE(names_in(t.w()).empty()) << "listing writes nothing";
  // A view's own camera is listed with it.
  const Result portal =
      run(t, {"catalogue", "--catalogue", std::string(PORTALSIM_SOURCE_DIR) + "/tests/portals/portal-20x33.toml"});
  ExpectSuccess(portal);
  EXPECT_TRUE(has(portal.out, " back_upper mmw back 200x200 raw 24x24;")) << portal.out;
  EXPECT_TRUE(has(portal.out, " upper mmw 200x200;")) << portal.out;
}

TEST(CliCatalogueCmd, ImagesWritesEveryImage) {
  TempDir t;
  const fs::path dir = t.w() / "images";
  const Result r = run(t, {"catalogue", "--images", dir.string()});
  ExpectSuccess(r);
  const std::vector<std::string> names = names_in(dir);
  int subject_images = 0, sprites = 0, noise = 0;
  for (const std::string& n : names) {
    SCOPED_TRACE(n);
    EXPECT_NE(n[0], '.') << "no hidden files (staging) may be left";
    ASSERT_GT(n.size(), 4u);
    EXPECT_EQ(n.substr(n.size() - 4), ".png");
    const ImageShape s = shape_of(dir / n);
    EXPECT_TRUE(s.ok) << "not a readable image";
    EXPECT_EQ(s.format, "png");
    if (n.rfind("subject", 0) == 0) {
      ++subject_images;
      const bool ir = has(n, "_ir.");
      EXPECT_EQ(s.width, ir ? 100 : 200);
      EXPECT_EQ(s.height, 200);
      EXPECT_EQ(s.channels, ir ? 3 : 1);
    } else if (n.rfind("noise", 0) == 0) {
      ++noise;  // the catalogue's noise_size
      EXPECT_EQ(s.width, 40);
      EXPECT_EQ(s.height, 40);
    } else {
      ++sprites;
    }
  }
  EXPECT_EQ(subject_images, 5 * 3) << "5 subjects x (MMW upper, MMW lower, IR)";
  EXPECT_EQ(noise, 5);
  // 31 objects, 11 of them with two drawings: 42 drawings, each an MMW and an IR sprite.
  EXPECT_EQ(sprites, 42 * 2);
  for (const char* n : {"subject1_upper.png", "subject5_ir.png", "gun_h_mmw.png", "gun_v_ir.png", "iron-handle_mmw.png",
                        "mobile-phone_ir.png", "knife-chef_v_mmw.png", "glasses_ir.png"})
    EXPECT_TRUE(std::find(names.begin(), names.end(), n) != names.end()) << n << " missing";
  EXPECT_EQ(names_in(t.w()), (std::vector<std::string>{"images"}));
}

TEST(CliCatalogueCmd, ImagesIntoAFileIsRejected) {
  TempDir t;
  const fs::path file = t.w() / "afile";
  spit(file, "keep me\n");
  const Result r = run(t, {"catalogue", "--images", (file / "images").string()});
  SCOPED_TRACE(describe(r));
  EXPECT_FALSE(r.signaled);
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(has(r.err, (file / "images").string()));
  EXPECT_EQ(slurp(file), "keep me\n");
}

}  // namespace
}  // namespace portalsim::test
