// portalsim bench (bench/speed/): the real binary in --quick mode, its devices, and what
// it measures on a device without fp64 (a described device: there is none here). No test
// asserts on a speed: only that every rate was measured, and that the ratios come from
// the measured rates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_binary.h"
#include "speed/availability.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using speed::Measure;

bool positive(const json& v) { return v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() > 0; }

// Checks one measured cell: its median of the repetitions, and its ratio to the loop.
void check_measured(const json& path, const char* measure, int repetitions) {
  SCOPED_TRACE(path["key"].get<std::string>() + " " + measure);
  const json& m = path[measure];
  ASSERT_TRUE(m.contains("per_s")) << m.dump();
  EXPECT_TRUE(positive(m["per_s"]));
  ASSERT_EQ(m["repetitions"].size(), static_cast<size_t>(repetitions));
  std::vector<double> r = m["repetitions"].get<std::vector<double>>();
  std::sort(r.begin(), r.end());
  EXPECT_DOUBLE_EQ(m["per_s"].get<double>(), r[r.size() / 2]);
  for (double v : r) EXPECT_TRUE(std::isfinite(v) && v > 0);
  if (path["loop"].contains("per_s")) {
    ASSERT_TRUE(m.contains("vs_loop"));
    EXPECT_NEAR(m["vs_loop"].get<double>(), m["per_s"].get<double>() / path["loop"]["per_s"].get<double>(),
                1e-9 * m["vs_loop"].get<double>());
  }
}

TEST(BenchCommand, QuickRunMeasuresEveryPath) {
  TempDir t;
  const Result r = finish(start(t.cap(), {"bench", "--quick", "--json", "--dir", t.w().string()}), 600);
  SCOPED_TRACE(describe(r));
  ASSERT_TRUE(r.exited && r.status == 0);
  EXPECT_TRUE(has(r.err, "portalsim bench: 1/")) << "no progress line";
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["quick"].get<bool>());
  const int reps = j["repetitions"].get<int>();
  EXPECT_EQ(reps, 3);
  EXPECT_TRUE(positive(j["memory"]["write_bytes_per_s"]));
  EXPECT_TRUE(positive(j["disk"]["write_bytes_per_s"]));
  EXPECT_TRUE(j["device"]["fp64"].get<bool>()) << "PoCL on this machine offers cl_khr_fp64";
  std::vector<std::string> keys;
  for (const json& p : j["paths"]) {
    keys.push_back(p["key"]);
    for (const char* m : {"kernel", "exact", "reference", "end_to_end"}) check_measured(p, m, reps);
    if (p["key"] != "physics_images") check_measured(p, "loop", reps);
    EXPECT_TRUE(positive(p["kernel"]["memory_share"]));
    EXPECT_TRUE(positive(p["end_to_end"]["disk_share"]));
    EXPECT_TRUE(positive(p["end_to_end"]["bytes_per_scenario"]));
  }
  EXPECT_EQ(keys, (std::vector<std::string>{"features", "images", "noisy_images", "physics_images", "annotations"}));
  EXPECT_TRUE(fs::is_empty(t.w())) << "the end-to-end runs and the disk test leave nothing";
}

TEST(BenchCommand, ListDevicesNamesPocl) {
  TempDir t;
  const Result r = finish(start(t.cap(), {"bench", "--list-devices"}));
  SCOPED_TRACE(describe(r));
  ASSERT_TRUE(r.exited && r.status == 0);
  EXPECT_TRUE(has(r.out, "Portable Computing Language / "));
  EXPECT_TRUE(has(r.out, "fp64 yes"));
}

TEST(BenchCommand, UnknownDeviceListsTheDevices) {
  TempDir t;
  const Result r = finish(start(t.cap(), {"bench", "--quick", "--device", "no-such-device", "--dir", t.w().string()}));
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.exited && r.status == 2);
  EXPECT_TRUE(has(r.err,
                  "--device: no OpenCL device matches \"no-such-device\"; the devices are: "
                  "Portable Computing Language / "));
  EXPECT_TRUE(r.out.empty());
}

TEST(BenchCommand, WithoutFp64SkipsTheExactTierAndPhysicsEndToEnd) {
  TempDir t;
  const Result r = finish(start(t.cap(), {"bench", "--quick", "--json", "--without-fp64", "--paths",
                                          "features,physics_images", "--dir", t.w().string()}),
                          600);
  SCOPED_TRACE(describe(r));
  ASSERT_TRUE(r.exited && r.status == 0);
  EXPECT_TRUE(has(r.err, "has no fp64"));
  const json j = json::parse(r.out);
  ASSERT_EQ(j["paths"].size(), 2u);
  const json &features = j["paths"][0], &physics = j["paths"][1];
  EXPECT_FALSE(j["device"]["fp64"].get<bool>());
  EXPECT_TRUE(j.contains("fp64_note"));
  // The note on stderr speaks of the paths asked for, as the report's does (issue 36).
  EXPECT_TRUE(has(r.err, "portalsim bench: " + j["fp64_note"].get<std::string>())) << "stderr and the report differ";
  for (const char* other : {"noisy_images", "annotations", ", images"})
    EXPECT_FALSE(has(r.err, other)) << "the note names a path not asked for: " << other;
  for (const json* p : {&features, &physics}) {
    EXPECT_TRUE((*p)["exact"].contains("skipped"));
    check_measured(*p, "kernel", 3);
    check_measured(*p, "reference", 3);
  }
  check_measured(features, "end_to_end", 3);
  EXPECT_TRUE(physics["end_to_end"].contains("skipped"));
}

OpenCLDeviceInfo device(bool fp64) { return OpenCLDeviceInfo{"Some platform / a GPU", "gpu", 64, fp64}; }

TEST(BenchAvailability, WithoutFp64TheExactTierAndPhysicsEndToEndDoNotRun) {
  const auto paths = portalsim::speed::speed_paths();
  ASSERT_EQ(paths.size(), 5u);
  for (const auto& p : paths) {
    SCOPED_TRACE(p.key);
    EXPECT_FALSE(why_not(p, Measure::exact, device(false)).empty());
    EXPECT_TRUE(why_not(p, Measure::kernel, device(false)).empty());
    EXPECT_TRUE(why_not(p, Measure::reference, device(false)).empty());
    EXPECT_EQ(why_not(p, Measure::end_to_end, device(false)).empty(), p.key != "physics_images");
    EXPECT_EQ(why_not(p, Measure::loop, device(false)).empty(), p.key != "physics_images");
  }
  const std::string note = fp64_note(paths, device(false));
  EXPECT_TRUE(has(note, "Some platform / a GPU has no fp64"));
  EXPECT_TRUE(has(note, "the exact tier is not measured"));
  EXPECT_TRUE(has(note, "Paths that run in full: features, images, noisy_images, annotations."));
  EXPECT_TRUE(has(note, "Paths that run in part: physics_images without end to end"));
}

TEST(BenchAvailability, WithFp64EverythingButThePhysicsLoopRuns) {
  const auto paths = portalsim::speed::speed_paths();
  for (const auto& p : paths)
    for (Measure m : portalsim::speed::kMeasures)
      EXPECT_EQ(why_not(p, m, device(true)).empty(), m != Measure::loop || p.key != "physics_images")
          << p.key << " " << measure_key(m);
  EXPECT_EQ(fp64_note(paths, device(true)), "");
}

}  // namespace
}  // namespace portalsim::test
