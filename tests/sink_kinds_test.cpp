// The sink kinds' registry (host/sink/sink_kinds.h): every file a run writes is a kind's,
// in the order the kinds open, and what --format takes is what the kinds answer.
#include "sink/sink_kinds.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "run_binary.h"

namespace portalsim::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> outputs_of(const fs::path& dir) {
  std::ifstream in(dir / "manifest.json");
  const nlohmann::json m = nlohmann::json::parse(in);
  std::vector<std::string> names;
  for (const nlohmann::json& o : m.at("outputs")) names.push_back(o.at("name"));
  return names;
}

const SinkKind* kind_named(std::string_view name) {
  for (const SinkKind* k : sink_kinds())
    if (k->name == name) return k;
  return nullptr;
}

TEST(SinkKinds, EachFileARunWritesIsAKindsInTheOrderTheKindsOpen) {
  TempDir t;
  const Result all = finish(start(t.cap(), {"generate", "--count", "6", "--what", "both", "--format", "csv,arff,npy,h5",
                                            "--annotations", "--quiet", "--out", (t.w() / "all").string()}),
                            300);
  ASSERT_TRUE(all.exited && all.status == 0) << describe(all);
  // --format's own order among the tables; the kinds' order otherwise.
  EXPECT_EQ(outputs_of(t.w() / "all"), (std::vector<std::string>{"scenarios.csv", "features.csv", "features.arff",
                                                                 "features.npy", "data.h5", "annotations.json"}));
  const Result npy = finish(start(t.cap(), {"generate", "--count", "6", "--what", "images", "--format", "npy",
                                            "--quiet", "--out", (t.w() / "npy").string()}),
                            300);
  ASSERT_TRUE(npy.exited && npy.status == 0) << describe(npy);
  std::vector<const SinkKind*> seen;
  for (const fs::path& dir : {t.w() / "all", t.w() / "npy"})
    for (const std::string& f : outputs_of(dir)) {
      const SinkKind* k = sink_kind_of(f);
      ASSERT_NE(k, nullptr) << dir << ": " << f << " is no kind's";
      ASSERT_NE(k->join, nullptr) << f;
      EXPECT_TRUE(k->writes(f));
      seen.push_back(k);
    }
  EXPECT_EQ(sink_kind_of("upper.npy"), kind_named("<tensor>.npy"));
  EXPECT_EQ(sink_kind_of("features.npy"), kind_named("features.<format>"));
  const SinkKind* coco = sink_kind_of("annotations.json");
  ASSERT_NE(coco, nullptr);
  EXPECT_EQ(coco->join("annotations.json"), JoinAs::refused);
  // Every kind but the image folders (the manifest's `images` entry) wrote a file.
  for (const SinkKind* k : sink_kinds())
    if (k != kind_named("images/")) {
      EXPECT_NE(std::find(seen.begin(), seen.end(), k), seen.end()) << k->name;
    }
}

TEST(SinkKinds, FormatValuesAndHelpAreTheKinds) {
  EXPECT_EQ(format_values(), (std::vector<std::string>{"arff", "csv", "npy", "h5"}));
  for (const SinkKind* k : sink_kinds())
    if (!k->format_help.empty()) {
      EXPECT_NE(format_help().find(k->format_help), std::string::npos) << k->name;
    }
  TempDir t;
  const Result r = finish(
      start(t.cap(), {"generate", "--count", "4", "--format", "arff,parquet", "--out", (t.w() / "o").string()}), 120);
  EXPECT_TRUE(r.exited && r.status == 2) << describe(r);
  EXPECT_NE(r.err.find("--format: \"parquet\" is not arff, csv, npy or h5"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(t.w() / "o"));
}

}  // namespace
}  // namespace portalsim::test
