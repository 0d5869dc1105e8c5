// When the OpenCL ICD loader finds no platform, the message says why from the loader's own
// search (host/backend/opencl/drivers.h): no .icd file, or the driver that does not load with
// the loader's reason. The loader drops a failing driver silently, so without this a driver
// built for a newer C++ runtime looked like no driver at all (issue 63).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "run_binary.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

// `portalsim bench --list-devices` with `vendors` as OCL_ICD_VENDORS.
Result list_devices(const TempDir& t, const std::string& vendors) {
  return finish(
      start_program(t.cap(), "/usr/bin/env", {"OCL_ICD_VENDORS=" + vendors, kBinary, "bench", "--list-devices"}));
}

TEST(OpenCLDrivers, ADriverThatDoesNotLoadIsNamedWithTheLoadersReason) {
  TempDir t;
  const fs::path vendors = t.w() / "vendors", library = t.w() / "libbroken-icd.so";
  fs::create_directories(vendors);
  spit(library, std::string(256, 'x'));  // no ELF header (shorter, and the loader says "file too short")
  spit(vendors / "broken.icd", library.string() + "\n");
  const Result r = list_devices(t, vendors.string());
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5) << "5: the OpenCL environment";
  EXPECT_TRUE(has(r.err, "no OpenCL platform found"));
  EXPECT_TRUE(has(r.err, (vendors / "broken.icd").string() + " names " + library.string() + ", which does not load: "));
  EXPECT_TRUE(has(r.err, "invalid ELF header")) << "the loader's own message";
  EXPECT_FALSE(has(r.err, "pocl-opencl-icd")) << "a driver is installed: installing one is not the fix";
}

TEST(OpenCLDrivers, AMissingLibraryNamedByOneIcdFileIsNamed) {
  TempDir t;
  const fs::path icd = t.w() / "gone.icd", library = t.w() / "no-such-dir" / "libgone.so.1";
  spit(icd, "  " + library.string() + "  \n");
  const Result r = list_devices(t, icd.string());
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5);
  EXPECT_TRUE(has(r.err, icd.string() + " names " + library.string() + ", which does not load: "));
  EXPECT_TRUE(has(r.err, "No such file or directory"));
}

TEST(OpenCLDrivers, NoIcdFileAsksForADriver) {
  TempDir t;
  const fs::path vendors = t.w() / "empty-vendors";
  fs::create_directories(vendors);
  spit(vendors / "README", "not an .icd file\n");
  const Result r = list_devices(t, vendors.string());
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 5);
  EXPECT_TRUE(
      has(r.err, "no OpenCL driver is installed: " + vendors.string() + " (OCL_ICD_VENDORS) holds no .icd file"));
  EXPECT_TRUE(has(r.err, "apt-get install pocl-opencl-icd"));
  EXPECT_TRUE(has(r.err, "--backend reference works without OpenCL"));
}

// The system's own driver, named alone, still works: the search changes no outcome.
TEST(OpenCLDrivers, TheSystemsDriverNamedAloneLoads) {
  TempDir t;
  const Result r = list_devices(t, "/etc/OpenCL/vendors/pocl.icd");
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 0);
  EXPECT_TRUE(has(r.out, "Portable Computing Language"));
}

}  // namespace
}  // namespace portalsim::test
