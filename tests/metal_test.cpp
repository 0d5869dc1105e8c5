// Zone-metal accumulation: the thesis's worked examples exact on both backends, the
// clamp at the extremes, and the model behind the cells the thesis does not give.
#include <gtest/gtest.h>

#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;

std::vector<int> zones(Backend& b, const std::vector<std::string>& objects, int subject = 0,
                       const ModelSettings& m = {}) {
  Scenario s = parse_object_list(catalogue(), objects);
  s.subject = subject;
  return test::metal_zones(b, s, m);
}

class MetalBothBackends : public test::BothBackends {};

TEST_P(MetalBothBackends, ThesisGunInRightAbdomen) {
  auto b = backend();
  EXPECT_EQ(zones(*b, {"none", "none", "none", "Gun"}),
            (std::vector<int>{193, 112, 75, 2, 1, 1, 96, 200, 200, 190, 196, 53, 53, 94, 64, 82, 53, 200, 200}));
}

TEST_P(MetalBothBackends, ThesisIronPipeInLeftChest) {
  auto b = backend();
  EXPECT_EQ(zones(*b, {"none", "none", "metal-barrel"}),
            (std::vector<int>{197, 131, 108, 88, 95, 106, 192, 200, 200, 197, 199, 54, 54, 75, 44, 84, 137, 200, 200}));
}

TEST_P(MetalBothBackends, ThesisMobileInLeftChestAndDiskInRightThigh) {
  auto b = backend();
  EXPECT_EQ(zones(*b, {"none", "none", "Mobile", "none", "none", "none", "compact-disk"}),
            (std::vector<int>{200, 183, 165, 136, 137, 142, 193, 200, 200, 198, 199, 185, 185, 195, 176, 175, 190, 200,
                              200}));
}

TEST_P(MetalBothBackends, EmptyScenarioGivesTheSubjectsBase) {
  auto b = backend();
  for (int s = 0; s < static_cast<int>(catalogue().subjects.size()); ++s) {
    const auto& base = catalogue().subjects[s].base_zones;
    EXPECT_EQ(zones(*b, {}, s), std::vector<int>(base.begin(), base.end())) << "subject " << s + 1;
  }
}

TEST_P(MetalBothBackends, HeaviestMetalEverywhereClampsAtOneNeverWraps) {
  auto b = backend();
  const std::vector<std::string> guns(kBuiltinRegions, "gun");
  for (int s = 0; s < static_cast<int>(catalogue().subjects.size()); ++s) {
    const std::vector<int> z = zones(*b, guns, s);
    for (int k = 0; k < kBuiltinZones; ++k) {
      EXPECT_GE(z[k], 1);
      EXPECT_LE(z[k], 200);
    }
    EXPECT_EQ(z[4], 1) << "the zone at the abdomen saturates";
  }
  // With detector noise at its largest, still inside [1, 200].
  ModelSettings m;
  m.metal_noise = 199;
  for (uint64_t seed : {0ull, ~0ull}) {
    m.seed = seed;
    for (int k : zones(*b, guns, 0, m)) {
      EXPECT_GE(k, 1);
      EXPECT_LE(k, 200);
    }
  }
}

TEST_P(MetalBothBackends, NonMetalObjectsLeaveTheDetectorAlone) {
  auto b = backend();
  const auto z = zones(*b, {"ceramic-plate", "cement-tile", "none", "ceramic-plate"});
  EXPECT_EQ(z, std::vector<int>(kBuiltinZones, 200));
}

INSTANTIATE_TEST_SUITE_P(, MetalBothBackends, ::testing::Values("reference", "opencl"));

// The cells that the thesis does not give follow the documented model
// (tools/metal_table.py): a response that falls with distance and grows with metal.
TEST(MetalTable, ModelCellsFallWithDistanceAndGrowWithMetal) {
  const Catalogue& c = catalogue();
  const auto cat = [&](const std::string& name) {
    for (size_t i = 0; i < c.metal_categories.size(); ++i)
      if (c.metal_categories[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int none = cat("none"), trace = cat("trace"), medium = cat("medium"), large = cat("large"),
            heavy = cat("heavy");
  ASSERT_GE(std::min({none, trace, medium, large, heavy}), 0);
  for (int r = 0; r < kBuiltinRegions; ++r) {
    int total_trace = 0, total_medium = 0, total_heavy = 0;
    for (int z = 0; z < kBuiltinZones; ++z) {
      EXPECT_EQ(c.influence[none][r][z], 0);
      total_trace += c.influence[trace][r][z];
      total_medium += c.influence[medium][r][z];
      total_heavy += c.influence[heavy][r][z];
    }
    EXPECT_GT(total_trace, 0) << "region " << r + 1;
    EXPECT_LT(total_trace, total_medium) << "region " << r + 1;
    EXPECT_LT(total_medium, total_heavy) << "region " << r + 1;
  }
  // Distance: a chest object moves the chest-height zone 4 more than the ankle zone 9,
  // and an ankle object the reverse.
  EXPECT_GT(c.influence[medium][2][3], c.influence[medium][2][8]);
  EXPECT_GT(c.influence[medium][11][8], c.influence[medium][11][3]);
  // The zones at the far ends of the panels (8, 9, 18, 19) see nothing from the chest.
  for (int z : {7, 8, 17, 18}) EXPECT_EQ(c.influence[heavy][0][z], 0);
  // Not copies of each other: every (category, region) row but "none" is distinct.
  for (int a = 1; a < static_cast<int>(c.influence.size()); ++a)
    for (int r = 0; r < kBuiltinRegions; ++r)
      for (int r2 = r + 1; r2 < kBuiltinRegions; ++r2) EXPECT_NE(c.influence[a][r], c.influence[a][r2]);
}

}  // namespace
}  // namespace portalsim
