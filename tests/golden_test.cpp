// Golden outputs: the reference backend's outputs for the thesis's worked examples (section
// 4.2 and figures 4.4-4.12) and one physics-model example, pinned by the XXH3 hashes in
// tests/golden/reference.txt. The reference must match them exactly; the kernels must match
// the reference within the tolerance table (plan/tolerance.h) in every tier. A change
// that moves kernel and reference together shows here.
//
// After an intended change to the reference's outputs, regenerate the hashes and commit
// them with the change (docs/dev/testing.md, "Golden outputs"):
//   PORTALSIM_UPDATE_GOLDEN=1 build/portalsim_tests --gtest_filter='Golden.*'
#include <gtest/gtest.h>
#include <xxhash.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "backend/compare.h"
#include "plan/tolerance.h"
#include "support.h"

namespace portalsim {
namespace {

using test::catalogue;

const std::string kHashFile = std::string(PORTALSIM_SOURCE_DIR) + "/tests/golden/reference.txt";

struct Example {
  const char* name;  // with what the thesis shows of it
  Model model;
  std::vector<std::pair<int, const char*>> objects;  // region (1-based, thesis 4.1) and object
};

// Subject 1 of the catalogue, as in the thesis's figures; objects by the thesis's words.
const std::vector<Example>& examples() {
  static const std::vector<Example> v{
      {"sec4.2-fig4.4-4.6-gun-right-abdomen", Model::thesis, {{4, "gun"}}},
      {"fig4.7-ceramic-tile-center-chest", Model::thesis, {{2, "ceramic-plate"}}},
      {"fig4.8-small-tile-right-thigh", Model::thesis, {{7, "cement-tile"}}},
      {"fig4.9-cd-center-chest-iron-pipe-center-abdomen", Model::thesis, {{2, "compact-disk"}, {5, "iron-pipe"}}},
      {"fig4.10-iron-plate-left-knee", Model::thesis, {{11, "metal-plate"}}},
      {"fig4.11-4.12-no-object", Model::thesis, {}},
      {"physics-gun-right-abdomen", Model::physics, {{4, "gun"}}},
  };
  return v;
}

Scenario scenario_of(const Example& e) {
  Scenario s;
  s.subject = 0;
  for (auto [region, object] : e.objects)
    s.objects[region - 1] = static_cast<int16_t>(test::variant_of(catalogue(), object));
  s.label = e.objects.empty() ? 0 : 1;
  return s;
}

// The plan of an example at the defaults (seed 0, the thesis's pattern noise, block 10),
// with a little sensor noise so that the noise draws are pinned too.
Plan plan_of(const Example& e, Tier tier, bool images) {
  Plan p;
  p.model.model = e.model;
  p.model.pixel_sigma = e.model == Model::thesis ? 2.0 : 0.0;
  p.model.metal_noise = 3;
  p.fidelity = tier_fidelity(tier);
  if (!images) p.images = 0;
  return p;
}

std::string hex(uint64_t h) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h));
  return b;
}

// "example output" -> XXH3 of that output's bytes for the example's one scenario.
std::map<std::string, std::string> hashes(const Example& e, const BatchOutput& o) {
  std::map<std::string, std::string> h;
  for (const ViewImages& v : o.views)
    if (!v.empty()) h[std::string(e.name) + " " + v.name] = hex(XXH3_64bits(v.of(0), v.pixels_per_image()));
  h[std::string(e.name) + " features"] = hex(XXH3_64bits(o.features_of(0), o.layout.image_features() * sizeof(float)));
  h[std::string(e.name) + " metal"] = hex(XXH3_64bits(o.metal_of(0), kBuiltinZones));
  return h;
}

Backend& reference_backend() {
  static auto ref = make_reference_backend(catalogue(), test::assets());
  return *ref;
}

// Each example alone, as scenario 0 of its own batch, on the reference.
BatchOutput reference_of(const Example& e) {
  BatchOutput o;
  reference_backend().run(test::batch_of({scenario_of(e)}), plan_of(e, Tier::exact, true), o);
  return o;
}

std::map<std::string, std::string> read_hashes() {
  std::map<std::string, std::string> h;
  std::ifstream in(kHashFile);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string name, output, hash;
    s >> name >> output >> hash;
    h[name + " " + output] = hash;
  }
  return h;
}

TEST(Golden, ReferenceMatchesTheCommittedHashes) {
  std::map<std::string, std::string> now;
  for (const Example& e : examples()) now.merge(hashes(e, reference_of(e)));
  if (const char* u = std::getenv("PORTALSIM_UPDATE_GOLDEN"); u && std::string(u) == "1") {
    std::ofstream out(kHashFile);
    out << "# XXH3-64 of the reference backend's outputs for the worked examples (tests/golden_test.cpp).\n"
           "# Regenerate after an intended change: PORTALSIM_UPDATE_GOLDEN=1 build/portalsim_tests "
           "--gtest_filter='Golden.*'\n";
    for (const auto& [key, hash] : now) out << key << " " << hash << "\n";
  }
  const std::map<std::string, std::string> committed = read_hashes();
  ASSERT_FALSE(committed.empty()) << kHashFile << ": no hashes";
  EXPECT_EQ(committed.size(), now.size()) << "examples or outputs added or gone: regenerate " << kHashFile;
  for (const auto& [key, hash] : now) {
    const auto it = committed.find(key);
    EXPECT_TRUE(it != committed.end() && it->second == hash)
        << key << ": the reference gives " << hash << ", " << kHashFile << " holds "
        << (it == committed.end() ? "nothing" : it->second)
        << "; if the change is intended, regenerate (docs/dev/testing.md, \"Golden outputs\")";
  }
}

TEST(Golden, KernelsMatchTheReferenceWithinTheTable) {
  auto cl = make_opencl_backend(catalogue(), test::assets(), test::runtime());
  for (const Example& e : examples()) {
    SCOPED_TRACE(e.name);
    const BatchOutput ref = reference_of(e);
    for (Tier tier : {Tier::exact, Tier::standard, Tier::fast}) {
      SCOPED_TRACE(tier_name(tier));
      const Tolerance tol = model_tolerance(e.model, tier);
      BatchOutput images, features;
      const Plan image_plan = plan_of(e, tier, true);
      if (e.model == Model::physics && image_plan.frames_approximated()) {
        // The fast tier draws the camera's frames as one draw of NETD / sqrt(frames), other
        // numbers than the reference's (held statistically:
        // Camera.FastTierFramesHaveTheSameDistribution), so its images are compared without noise.
        Plan quiet = image_plan;
        quiet.model.netd = 0;
        BatchOutput ref_quiet;
        reference_backend().run(test::batch_of({scenario_of(e)}), quiet, ref_quiet);
        cl->run(test::batch_of({scenario_of(e)}), quiet, images);
        EXPECT_EQ(check_tolerance(compare_outputs(images, ref_quiet), tol), "") << "images run, no noise";
      } else {
        cl->run(test::batch_of({scenario_of(e)}), image_plan, images);
        // The reference follows the plan's pixel draws (the fast tier's Irwin-Hall).
        BatchOutput ref_draws;
        const bool other_draws = image_plan.fidelity.draw != NoiseDraw::box_muller;
        if (other_draws) reference_backend().run(test::batch_of({scenario_of(e)}), image_plan, ref_draws);
        EXPECT_EQ(check_tolerance(compare_outputs(images, other_draws ? ref_draws : ref), tol), "") << "images run";
      }
      // The features-only run: the fast tier's own paths. Its noise is drawn per feature,
      // other numbers than the reference's (held statistically: ExtremeBlackWhite,
      // Physics.RawGridFeatureNoiseMatchesTheReference), so it is compared without noise.
      if (tier == Tier::fast) {
        Plan quiet = plan_of(e, tier, false);
        quiet.model.pixel_sigma = quiet.model.netd = 0;
        BatchOutput ref_quiet;
        quiet.images = plan_of(e, tier, true).images;
        reference_backend().run(test::batch_of({scenario_of(e)}), quiet, ref_quiet);
        quiet.images = 0;
        cl->run(test::batch_of({scenario_of(e)}), quiet, features);
        EXPECT_EQ(check_tolerance(compare_outputs(features, ref_quiet), tol), "") << "features-only run, no noise";
        continue;
      }
      cl->run(test::batch_of({scenario_of(e)}), plan_of(e, tier, false), features);
      EXPECT_EQ(check_tolerance(compare_outputs(features, ref), tol), "") << "features-only run";
    }
  }
}

}  // namespace
}  // namespace portalsim
