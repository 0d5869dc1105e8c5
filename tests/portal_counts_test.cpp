// A portal of other counts through the command line: the test portal of
// tests/portals/portal-20x33.toml (20 regions, 33 zones, front and back MMW and IR views)
// in every format generate writes, its shards merged into the whole run's bytes, and its
// dataset card telling what the data hold. The kernels' parity on it is in extremes_test.cpp
// (PortalCounts.*).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "run_binary.h"
#include "sink/h5_file.h"

namespace portalsim {
namespace {

namespace fs = std::filesystem;

const std::string kPortal = (fs::path(PORTALSIM_SOURCE_DIR) / "tests" / "portals" / "portal-20x33.toml").string();

std::string first_line(const fs::path& p) {
  const std::string t = test::slurp(p);
  return t.substr(0, t.find('\n'));
}

test::Result run(const test::TempDir& t, std::vector<std::string> args) {
  return test::finish(test::start_program(t.cap(), portalsim::test::kBinary, args), 300);
}

std::vector<std::string> spec_args() {
  return {"--catalogue", kPortal,       "--count", "80",      "--seed",        "4", "--rule", "gun", "--what", "both",
          "--format",    "h5,csv,arff", "--model", "physics", "--metal-noise", "2", "--quiet"};
}

std::vector<std::string> plus(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

const H5Dataset* dataset(const H5Layout& h5, const std::string& name) {
  for (const H5Dataset& d : h5.datasets)
    if (d.name == name) return &d;
  ADD_FAILURE() << "data.h5 has no dataset " << name;
  return nullptr;
}

TEST(PortalCounts, GenerateWritesTheCataloguesCountsAndShardsMergeToTheWholeRun) {
  test::TempDir t;
  const fs::path whole = t.w() / "whole", s0 = t.w() / "s0", s1 = t.w() / "s1", merged = t.w() / "merged";
  for (const auto& [args, out] :
       std::vector<std::pair<std::vector<std::string>, fs::path>>{{spec_args(), whole},
                                                                  {plus(spec_args(), {"--shard", "0/2"}), s0},
                                                                  {plus(spec_args(), {"--shard", "1/2"}), s1}}) {
    const test::Result r = run(t, plus(plus({"generate"}, args), {"--out", out.string()}));
    ASSERT_TRUE(r.exited && r.status == 0) << test::describe(r);
  }
  const test::Result m = run(t, {"merge", s0.string(), s1.string(), "--out", merged.string()});
  ASSERT_TRUE(m.exited && m.status == 0) << test::describe(m);
  for (const char* f : {"data.h5", "features.csv", "features.arff", "scenarios.csv", "manifest.json", "README.md"})
    EXPECT_TRUE(test::slurp(whole / f) == test::slurp(merged / f))
        << f << ": the merged shards differ from the whole run";

  // Every table and tensor has the catalogue's regions and zones.
  const std::string scen = first_line(whole / "scenarios.csv"), feat = first_line(whole / "features.csv");
  EXPECT_NE(scen.find(",region19,region20,label"), std::string::npos) << scen;
  EXPECT_EQ(scen.find("region21"), std::string::npos) << scen;
  EXPECT_NE(feat.find(",region20,zone1,"), std::string::npos) << feat;
  EXPECT_TRUE(feat.ends_with(",zone32,zone33,class")) << feat;
  EXPECT_NE(test::slurp(whole / "features.arff").find("@attribute zone33 "), std::string::npos);
  const H5Layout h5 = read_h5_layout((whole / "data.h5").string());
  const H5Dataset *metal = dataset(h5, "metal"), *objects = dataset(h5, "region_object"),
                  *labels = dataset(h5, "region_label"), *back_ir = dataset(h5, "back_ir"),
                  *features = dataset(h5, "features");
  ASSERT_TRUE(metal && objects && labels && back_ir && features);
  EXPECT_EQ(h5.rows, 80u);
  EXPECT_EQ(metal->dims, (std::vector<uint64_t>{33}));  // per row
  EXPECT_EQ(objects->dims, (std::vector<uint64_t>{20}));
  EXPECT_EQ(labels->dims, (std::vector<uint64_t>{20}));
  EXPECT_EQ(back_ir->dims, (std::vector<uint64_t>{200, 100, 3}));
  ASSERT_EQ(features->dims.size(), 1u);
  EXPECT_EQ(features->dims[0], 4u * 20 * 20 + 20) << "four pooled 200x200 views in blocks of 10, then 20 regions";
  for (const char* view : {"upper", "lower", "back_upper", "back_lower", "ir", "back_ir"}) dataset(h5, view);

  // The dataset card says what the data hold.
  const std::string card = test::slurp(whole / "README.md");
  for (const char* says : {"metal detector (33 zones)", "the object in each of the 20 regions",
                           "the image features, the 33 metal zones", "infrared camera views (ir, back_ir)",
                           "**View back_upper** has a camera of its own, over the run's parameters: raw grid 24x24."})
    EXPECT_NE(card.find(says), std::string::npos) << says;
  const std::string croissant = test::slurp(whole / "croissant.json");
  EXPECT_NE(croissant.find("metal detector: 33 zone values"), std::string::npos);
  EXPECT_NE(croissant.find("per region 1-20:"), std::string::npos);
  EXPECT_NE(croissant.find("IR camera, view back_ir (the back)"), std::string::npos);
}

// COCO: an image per scenario and view, the back views' among them, and the objects of the
// back regions in the back views' images.
TEST(PortalCounts, CocoHasEveryViewAndTheBackRegions) {
  test::TempDir t;
  const fs::path out = t.w() / "coco";
  const test::Result r = run(t, {"generate", "--catalogue", kPortal, "--count", "12", "--seed", "2", "--objects",
                                 "8..12", "--what", "images", "--annotations", "--quiet", "--out", out.string()});
  ASSERT_TRUE(r.exited && r.status == 0) << test::describe(r);
  const std::string coco = test::slurp(out / "annotations.json");
  for (const char* view : {"back_upper", "back_lower", "back_ir"})
    EXPECT_NE(coco.find(std::string("\"view\":\"") + view + "\""), std::string::npos) << view;
  size_t back_regions = 0;
  for (int r = 14; r <= 20; ++r)
    back_regions += coco.find("\"region\":" + std::to_string(r) + ",") != std::string::npos;
  EXPECT_GT(back_regions, 3u) << "objects in the back regions 14-20 are annotated";
  EXPECT_TRUE(fs::exists(out / "images" / "00000000" / "mask_back_ir.png"));
  // The thesis model reads no camera numbers, so its card names no view's own camera.
  const std::string card = test::slurp(out / "README.md");
  EXPECT_NE(card.find("**Sensor model:** `thesis`"), std::string::npos) << card;
  EXPECT_EQ(card.find("has a camera of its own"), std::string::npos) << card;
}

}  // namespace
}  // namespace portalsim
