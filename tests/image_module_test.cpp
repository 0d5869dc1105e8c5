// The OpenImageIO module (host/assets/oiio/codec.h): loaded only when an image file is read
// or written other than as PNG; found beside the binary, and from an installed bin/; and,
// when missing, an environment error (exit 5) naming it and where it was looked for.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "run_binary.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

constexpr const char* kModule = "libportalsim_oiio.so";

// `program` (a portalsim binary) with the dynamic loader telling, on stderr, each library
// it loads (LD_DEBUG=files: "file=NAME [0];  needed by ..." or "... dynamically loaded by").
Result run_traced(const TempDir& t, const std::string& program, const std::vector<std::string>& args) {
  std::vector<std::string> env_args{"LD_DEBUG=files", program};
  env_args.insert(env_args.end(), args.begin(), args.end());
  return finish(start_program(t.cap(), "/usr/bin/env", env_args));
}

std::vector<std::string> simulate_gun(const fs::path& out, const std::string& format) {
  return {"simulate", "--seed", "3", "--image-format", format, "--out", out.string(), "none", "none", "none", "gun"};
}

bool loads_openimageio(const Result& r) { return has(r.err, "file=libOpenImageIO.so"); }

TEST(ImageModule, LoadedOnlyWhenAnImageFileIsReadOrWrittenOtherThanPng) {
  TempDir t;
  const Result version = run_traced(t, portalsim::test::kBinary, {"--version"});
  ASSERT_TRUE(version.exited && version.status == 0) << describe(version);
  EXPECT_FALSE(loads_openimageio(version)) << describe(version);
  EXPECT_FALSE(has(version.err, kModule)) << describe(version);

  const Result png = run_traced(t, portalsim::test::kBinary, simulate_gun(t.w() / "png", "png"));
  ASSERT_TRUE(png.exited && png.status == 0) << describe(png);
  EXPECT_TRUE(fs::exists(t.w() / "png" / "upper.png"));
  EXPECT_FALSE(loads_openimageio(png)) << describe(png);

  const Result jpg = run_traced(t, portalsim::test::kBinary, simulate_gun(t.w() / "jpg", "jpg"));
  ASSERT_TRUE(jpg.exited && jpg.status == 0) << describe(jpg);
  EXPECT_TRUE(fs::exists(t.w() / "jpg" / "upper.jpg"));
  EXPECT_TRUE(has(jpg.err, kModule)) << describe(jpg);
  EXPECT_TRUE(loads_openimageio(jpg)) << describe(jpg);
}

// `cmake --install --component cli` into a fresh prefix: bin/portalsim finds the module
// under the prefix's lib folder and writes the same JPEG bytes as the build's binary.
TEST(ImageModule, FoundFromAnInstalledBin) {
  TempDir t;
  const fs::path prefix = t.w() / "prefix";
  const Result install = finish(start_program(t.cap(), "/usr/bin/cmake",
                                              {"--install", fs::path(portalsim::test::kBinary).parent_path().string(),
                                               "--component", "cli", "--prefix", prefix.string()}));
  ASSERT_TRUE(install.exited && install.status == 0) << describe(install);
  const fs::path installed = prefix / "bin" / "portalsim";
  ASSERT_TRUE(fs::exists(installed));
  const Result jpg = run_traced(t, installed.string(), simulate_gun(t.w() / "installed", "jpg"));
  ASSERT_TRUE(jpg.exited && jpg.status == 0) << describe(jpg);
  EXPECT_TRUE(has(jpg.err, (prefix / "lib" / "portalsim" / kModule).string())) << describe(jpg);
  const Result build = finish(start(t.cap(), simulate_gun(t.w() / "build", "jpg")));
  ASSERT_TRUE(build.exited && build.status == 0) << describe(build);
  for (const char* view : {"upper.jpg", "lower.jpg", "ir.jpg"})
    EXPECT_TRUE(slurp(t.w() / "installed" / view) == slurp(t.w() / "build" / view)) << view;
}

// A binary alone in a folder: PNG runs need nothing more; a JPEG run stops with exit 5 (the
// machine lacks something: docs/reference/exit-codes.md), naming the module and each place
// it looked, and leaves no output folder.
TEST(ImageModule, MissingIsAnEnvironmentErrorNamingWhereItLooked) {
  TempDir t;
  const fs::path alone = t.w() / "alone" / "bin" / "portalsim";
  fs::create_directories(alone.parent_path());
  fs::copy_file(portalsim::test::kBinary, alone);
  const Result png = finish(start_program(t.cap(), alone.string(), simulate_gun(t.w() / "png", "png")));
  EXPECT_TRUE(png.exited && png.status == 0) << describe(png);
  const Result jpg = finish(start_program(t.cap(), alone.string(), simulate_gun(t.w() / "jpg", "jpg")));
  EXPECT_TRUE(jpg.exited && jpg.status == 5) << describe(jpg);
  // Appended, not operator+ on a temporary: g++ 12 at -O1 warns falsely there (-Warray-bounds).
  std::string not_found = "OpenImageIO module ";
  not_found.append(kModule).append(", not found");
  EXPECT_TRUE(has(jpg.err, not_found)) << describe(jpg);
  EXPECT_TRUE(has(jpg.err, (alone.parent_path() / kModule).string())) << describe(jpg);
  EXPECT_TRUE(has(jpg.err, "images add-on, portalsim-" PORTALSIM_VERSION "-linux-x86_64-images.tar.gz"))
      << "a bundle without its add-on is told where the module is" << describe(jpg);
  EXPECT_FALSE(fs::exists(t.w() / "jpg"));
}

}  // namespace
}  // namespace portalsim::test
