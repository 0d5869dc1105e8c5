// The OpenCL backend's declared paths (backend/opencl/paths/paths.h): a fast path runs only
// where its gate applies, and where it does not the stage chain and pooling give the
// reference's outputs; table caches are keyed by every knob; launch structs are checked
// against the kernels' own argument counts.
#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <string>

#include "backend/compare.h"
#include "backend/opencl/device.h"
#include "backend/opencl/launch.h"
#include "backend/opencl/paths/paths.h"
#include "backend/opencl/table_key.h"
#include "backend/opencl/view_derive.h"
#include "plan/knobs.h"
#include "run_binary.h"
#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;

// The default catalogue with its MMW views' physics chain less the optics stage: a chain
// the physics_raw path (which blurs in the same pass) does not implement.
Catalogue without_mmw_optics() {
  Catalogue cat = catalogue();
  for (Sensor& s : cat.sensors)
    if (s.camera == Camera::mmw) s.physics_chain = {"radiometry", "sample", "netd", "mmw_display"};
  return cat;
}

TEST(OpenCLPaths, EachViewTakesTheFirstPathWhoseGateApplies) {
  const Catalogue& cat = catalogue();
  Plan plan;
  EXPECT_STREQ(opencl::view_path(plan, cat.sensors[0]).name(), "thesis_images");
  plan.model.model = Model::physics;
  EXPECT_STREQ(opencl::view_path(plan, cat.sensors[0]).name(), "physics_raw");
  EXPECT_STREQ(opencl::view_path(plan, cat.sensors[2]).name(), "ir_fused");
  plan.fidelity.fused = false;
  for (const Sensor& s : cat.sensors) EXPECT_STREQ(opencl::view_path(plan, s).name(), "stage_chain");
  plan.fidelity.fused = true;
  const Catalogue other = without_mmw_optics();
  EXPECT_STREQ(opencl::view_path(plan, other.sensors[0]).name(), "stage_chain");
}

// The fast paths are listed by name (CMake reads their files), not in an order of their own,
// so no view may have two whose gates apply: over both models, every tier, the window's
// variants, IR noise on and off, images and features-only runs, each view of the default
// catalogue has at most one fast view path, and each plan at most one features path.
TEST(OpenCLPaths, AtMostOneFastPathAppliesToAView) {
  const Catalogue& cat = catalogue();
  opencl::Device device(cat, assets(), *test::runtime());
  std::vector<std::unique_ptr<opencl::FeaturePath>> features;
#define PORTALSIM_TEST_FEATURE_PATH(name) features.push_back(opencl::name##_path(device));
  PORTALSIM_FEATURE_PATHS(PORTALSIM_TEST_FEATURE_PATH)
#undef PORTALSIM_TEST_FEATURE_PATH
  ASSERT_EQ(opencl::view_paths().size(), 3u) << "thesis_images, physics_raw and ir_fused";
  ASSERT_EQ(features.size(), 2u) << "thesis_sparse_features and physics_raw_features";
  std::set<std::string> seen;
  for (const Model model : {Model::thesis, Model::physics})
    for (const Tier tier : {Tier::exact, Tier::standard, Tier::fast})
      for (int window = 0; window < 3; ++window)
        for (const double ir_netd : {0.0, 0.05})
          for (const bool images : {true, false}) {
            Plan plan;
            plan.fidelity = tier_fidelity(tier);
            plan.model.model = model;
            plan.model.window_auto = window == 1;
            if (window == 2) plan.model.drawn[PS_DRAWN_WINDOW_LO] = {.lo = 280, .hi = 290};
            plan.model.ir_netd = ir_netd;
            if (!images) plan.images = 0;
            const std::string what = std::string(model_name(model)) + " " + tier_name(tier) + " window " +
                                     std::to_string(window) + (images ? " images" : " features");
            for (const Sensor& s : cat.sensors) {
              int applying = 0;
              for (const opencl::ViewPath* p : opencl::view_paths())
                if (p->applies(plan, s)) ++applying, seen.insert(p->name());
              EXPECT_LE(applying, 1) << what << ", view " << s.name;
            }
            int applying = 0;
            for (const auto& f : features)
              if (f->applies(plan, cat.sensors[0])) ++applying, seen.insert(f->name());
            EXPECT_LE(applying, 1) << what;
          }
  EXPECT_EQ(seen, (std::set<std::string>{"thesis_images", "physics_raw", "ir_fused", "thesis_sparse_features",
                                         "physics_raw_features"}))
      << "each path applies somewhere in this matrix, so the check above means something";
}

// Each gate decides its path's variant too (render() decides nothing), and the backend's
// paths(), which --timing prints, names what run() takes, view by view.
TEST(OpenCLPaths, EachGateDecidesItsVariantAndTimingNamesIt) {
  const Catalogue& cat = catalogue();
  Plan plan = test::physics_plan();
  const Sensor &upper = cat.sensors[0], &ir = cat.sensors[2];
  EXPECT_EQ(opencl::describe("physics_raw", opencl::view_route(plan, upper).gate), "physics_raw (fixed window)");
  plan.model.window_auto = true;
  EXPECT_EQ(opencl::describe("physics_raw", opencl::view_route(plan, upper).gate), "physics_raw (automatic window)");
  plan.model.ir_netd = 0.05;
  EXPECT_STREQ(opencl::view_route(plan, ir).gate.variant_name, "surface, noise and display fused");
  plan.model.ir_netd = 0;
  EXPECT_STREQ(opencl::view_route(plan, ir).gate.variant_name, "surface and display fused");

  auto cl = make_opencl_backend(cat, assets(), test::runtime());
  Plan features = test::physics_plan();
  features.images = 0;
  features.fidelity = tier_fidelity(Tier::fast);
  EXPECT_EQ(cl->paths(features), (std::vector<std::string>{"features: physics_raw_features (tabulated)"}));
  features.model.jitter = 3;  // objects move: no pair tables
  EXPECT_EQ(cl->paths(features), (std::vector<std::string>{"features: physics_raw_features (untabulated)"}));
  EXPECT_EQ(cl->rendered_views(features), std::vector<int>{}) << "a features path renders no view";
  Plan thesis;
  thesis.images = 1u << 2;  // the IR view alone, and the MMW views pooled for the features
  EXPECT_EQ(cl->paths(thesis),
            (std::vector<std::string>{"upper: thesis_images", "lower: thesis_images", "ir: thesis_images",
                                      "features: pooled from the rendered views"}));
  EXPECT_EQ(cl->rendered_views(thesis), (std::vector<int>{0, 1, 2}));
  thesis.features = false;
  EXPECT_EQ(cl->paths(thesis), (std::vector<std::string>{"ir: thesis_images"}));
  EXPECT_EQ(cl->rendered_views(thesis), std::vector<int>{2});
  // The reference renders every view it keeps or pools.
  features.model.jitter = 0;
  EXPECT_EQ(make_reference_backend(cat, assets())->rendered_views(features), (std::vector<int>{0, 1}));
}

// A features-only physics run under the block-mean model (the fast tier's), on views whose
// chain physics_raw does not implement: its gate fails, so the views are rendered stage by
// stage and pooled, and the features are the reference's within the physics model's dense
// bounds. This used to stop on a logic_error ("the raw grid alone needs the physics fast path").
TEST(OpenCLPaths, AFailedGateFallsBackToTheStageChainAndMatchesTheReference) {
  const Catalogue cat = without_mmw_optics();
  const SceneBatch batch = test::batch_of(test::coverage(cat, 200, 4));
  auto cl = make_opencl_backend(cat, assets(), test::runtime());
  auto ref = make_reference_backend(cat, assets());
  auto usual = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (Tier tier : {Tier::fast, Tier::standard}) {
    SCOPED_TRACE(tier_name(tier));
    Plan plan = test::physics_plan();
    plan.images = 0;
    plan.fidelity = tier_fidelity(tier);
    plan.fidelity.noise = NoiseModel::block_mean;
    // The plan would take the raw-grid features path on the usual chains; not on these.
    ASSERT_EQ(test::features_path(*usual, plan), "physics_raw_features");
    ASSERT_EQ(test::features_path(*cl, plan), Backend::kPooledFeatures);
    BatchOutput a, b;
    ASSERT_NO_THROW(cl->run(batch, plan, a));
    ref->run(batch, plan, b);
    const OutputDiff d = compare_outputs(a, b);
    const Tolerance t = model_tolerance(Model::physics, Tier::standard);  // the dense path's bounds
    EXPECT_LE(d.feature_max_abs, t.feature_max_abs);
    EXPECT_LE(d.feature_mean_abs, t.feature_mean_abs);
    EXPECT_EQ(d.metal_exact, 1.0);
  }
}

// A value of `k` other than the one in `p`, set through the registry.
void change(Plan& p, const Knob& k) {
  switch (k.kind) {
    case KnobKind::on_off:
      return k.set(p, k.get(p).get<bool>() ? 0 : 1);
    case KnobKind::choice: {
      const std::string now = k.get(p).get<std::string>();
      return k.set(p, now == k.choices[0] ? 1 : 0);
    }
    case KnobKind::grid:
      return k.set(p, 3 * 65536 + 5);
    case KnobKind::range:
      return k.set_range(p, k.min, k.max);
    case KnobKind::integer:
    case KnobKind::number:
      return k.set(p, k.get(p).get<double>() == k.max ? k.min : k.max);
  }
}

// Every knob of the registry is in a table's key: changing any one gives another key, so a
// knob added later cannot leave a stale table in use.
TEST(OpenCLPaths, TableKeysChangeWithEveryKnob) {
  const Plan base;
  const std::string key = opencl::table_key(base, "view=0");
  EXPECT_EQ(key, opencl::table_key(base, "view=0"));
  EXPECT_NE(key, opencl::table_key(base, "view=1"));
  for (const Knob& k : knobs()) {
    SCOPED_TRACE(k.key);
    Plan p = base;
    change(p, k);
    ASSERT_NE(k.get(p), k.get(base)) << "the test did not change the knob";
    EXPECT_NE(opencl::table_key(p, "view=0"), key);
  }
}

// The tables in use follow the knobs: one backend run under a knob's new value gives what a
// fresh backend gives (physics images use the per-view parameter tables, features-only
// runs the raw-grid and sparse tables).
TEST(OpenCLPaths, ChangedKnobsGiveFreshTables) {
  const SceneBatch batch = test::batch_of(test::coverage(catalogue(), 64, 3, false));
  auto kept = make_opencl_backend(catalogue(), assets(), test::runtime());
  struct Case {
    Model model;
    bool images;
    const char* knob;
    const char* first;
    const char* second;
  };
  for (const Case& c :
       {Case{Model::physics, true, "worn_minutes", "5", "60"}, Case{Model::physics, true, "illumination", "293", "50"},
        Case{Model::physics, false, "mmw_raw", "28x28", "20x20"},
        Case{Model::thesis, false, "pattern_noise", "on", "off"}, Case{Model::thesis, false, "block", "10", "20"}}) {
    SCOPED_TRACE(std::string(c.knob) + " " + c.second);
    Plan plan;
    plan.model.model = c.model;
    plan.fidelity = tier_fidelity(Tier::fast);
    if (!c.images) plan.images = 0;
    const Knob& k = *find_knob(c.knob);
    set_knob(plan, k, c.first, c.knob);
    BatchOutput first, again, fresh;
    kept->run(batch, plan, first);
    set_knob(plan, k, c.second, c.knob);
    kept->run(batch, plan, again);
    make_opencl_backend(catalogue(), assets(), test::runtime())->run(batch, plan, fresh);
    EXPECT_TRUE(again.features == fresh.features) << "features from stale tables";
    for (size_t v = 0; v < fresh.views.size(); ++v)
      EXPECT_TRUE(again.views[v].pixels == fresh.views[v].pixels) << "view " << v << " from stale tables";
    EXPECT_TRUE(again.features != first.features || again.views[0].pixels != first.views[0].pixels)
        << "the knob changed nothing: the case cannot tell";
  }
}

// One cache holds every view's derivation (view_derive.h): trying knob after knob, as a
// long-lived serve does, keeps at most its capacity; a derivation in use stays whole when
// the cache drops it; one made again after it was dropped is the same.
TEST(OpenCLPaths, ViewDerivationsAreBoundedAndKeepWhatIsInUse) {
  const Catalogue& cat = catalogue();
  opencl::ViewDerivations derived(cat, assets(), test::runtime()->context());
  Plan plan = test::physics_plan();
  const std::shared_ptr<opencl::ViewDerived> first = derived(plan, 0);
  const PsViewLaunch first_launch = first->L;
  ASSERT_GE(derived.capacity(), 2 * cat.sensors.size()) << "a run's own derivations must fit";
  for (int k = 0; k < static_cast<int>(3 * derived.capacity()); ++k) {
    plan.model.illumination = 250 + k;
    for (int view = 0; view < static_cast<int>(cat.sensors.size()); ++view) derived(plan, view);
    ASSERT_LE(derived.size(), derived.capacity());
  }
  EXPECT_EQ(first->model.illumination, 293.0) << "the derivation in use was changed";
  plan.model.illumination = 293;
  const std::shared_ptr<opencl::ViewDerived> again = derived(plan, 0);
  EXPECT_NE(again.get(), first.get()) << "the first derivation was never dropped: the case cannot tell";
  EXPECT_EQ(std::memcmp(&again->L, &first_launch, sizeof first_launch), 0);
  EXPECT_EQ(derived(plan, 0).get(), again.get()) << "a derivation is made once per key";
  // The noise-free derivation (the physics features path's raw grid) is another entry.
  EXPECT_EQ(derived(plan, 0, true)->model.netd, 0.0);
  EXPECT_EQ(derived(plan, 0)->model.netd, plan.model.netd);
}

// A run whose raw grid is drawn from a list of the most grids uses every grid's derivations
// in every batch (each grid's part, images and the features path's noise-free ones): the
// cache holds them all, so none is made again batch after batch.
TEST(OpenCLPaths, ViewDerivationsHoldEveryDrawnGridsPart) {
  const Catalogue& cat = catalogue();
  opencl::ViewDerivations derived(cat, assets(), test::runtime()->context());
  derived.hold_parts(kMaxRawGrids);
  Plan plan = test::physics_plan();
  std::vector<std::shared_ptr<opencl::ViewDerived>> made;
  for (int round = 0; round < 2; ++round) {
    size_t k = 0;
    for (int g = 1; g <= static_cast<int>(kMaxRawGrids); ++g) {
      plan.model.raw_width = plan.model.raw_height = 10 + g;
      for (int view = 0; view < static_cast<int>(cat.sensors.size()); ++view)
        for (const bool noise_free : {false, true}) {
          const std::shared_ptr<opencl::ViewDerived> d = derived(plan, view, noise_free);
          if (round == 0)
            made.push_back(d);
          else
            EXPECT_EQ(d.get(), made[k].get()) << "grid " << g << " view " << view << " made again";
          ++k;
        }
    }
  }
  EXPECT_LE(derived.size(), derived.capacity());
}

// After more knob settings than the cache holds, a backend gives the first setting's bytes
// again: images (the physics parameter tables) and features-only runs (the sparse tables).
TEST(OpenCLPaths, ARunAfterTheCacheDroppedItsTablesGivesTheSameBytes) {
  const SceneBatch batch = test::batch_of(test::coverage(catalogue(), 32, 3, false));
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  for (const bool physics : {true, false}) {
    SCOPED_TRACE(physics ? "physics images" : "thesis features");
    Plan plan = physics ? test::physics_plan() : Plan{};
    if (!physics) plan.images = 0;
    const Knob& k = *find_knob(physics ? "illumination" : "block");
    BatchOutput first, again;
    cl->run(batch, plan, first);
    const size_t settings = 4 * catalogue().sensors.size() + 2;
    for (size_t i = 1; i <= settings; ++i) {
      Plan other = plan;
      k.set(other, physics ? 250.0 + double(i) : double(10 + i));
      BatchOutput o;
      cl->run(batch, other, o);
    }
    cl->run(batch, plan, again);
    EXPECT_TRUE(again.features == first.features);
    for (size_t v = 0; v < first.views.size(); ++v) EXPECT_TRUE(again.views[v].pixels == first.views[v].pixels);
  }
}

// A launch struct set on a kernel of another signature is refused, naming both counts.
TEST(OpenCLPaths, LaunchStructsMatchTheirKernels) {
  opencl::Kernels K(*test::runtime(), Fidelity{}, opencl::KernelCounts::of(test::catalogue()));
  EXPECT_NO_THROW(opencl::PoolRegionsArgs{}.set(K["pool_regions"], false));
  try {
    opencl::PoolBlocksArgs{}.set(K["pool_regions"], false);
    FAIL() << "pool_blocks' arguments were taken by pool_regions";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("pool_regions takes 9 arguments"), std::string::npos) << e.what();
  }
}

// A POCL_CACHE_DIR that is a file: PoCL fails the build with no word of its cache ("failed
// to build the program"); the message must name the cache and what is wrong with it, as
// the machine's problem (exit 5), and write nothing.
TEST(OpenCLRuntime, APoclCacheThatIsAFileIsNamed) {
  namespace fs = std::filesystem;
  test::TempDir t;
  const fs::path cache = t.w() / "cache";
  test::spit(cache, "not a folder\n");
  const test::Result r = test::finish(test::start_program(t.cap(), "/usr/bin/env",
                                                          {"POCL_CACHE_DIR=" + cache.string(), portalsim::test::kBinary,
                                                           "simulate", "gun", "--out", (t.w() / "o").string()}));
  SCOPED_TRACE(test::describe(r));
  EXPECT_TRUE(r.exited && r.status == 5) << "5: the OpenCL environment";
  EXPECT_NE(r.err.find("PoCL's kernel cache, " + cache.string()), std::string::npos);
  EXPECT_NE(r.err.find("is a file"), std::string::npos);
  EXPECT_FALSE(fs::exists(t.w() / "o"));
}

// PORTALSIM_KERNEL_PROGRAM (tools/mutate.sh) replaces the built-in program with a file's:
// the file is what PoCL builds, and a file that cannot be read is named (exit 5).
TEST(OpenCLRuntime, KernelProgramFromTheEnvironmentIsTheOneBuilt) {
  namespace fs = std::filesystem;
  test::TempDir t;
  const std::string program = OpenCLRuntime::source();
  ASSERT_NE(program.find("kernel void stage_window"), std::string::npos);
  test::spit(t.w() / "same.cl", program);
  test::spit(t.w() / "broken.cl", program + "\nthis is not OpenCL\n");
  const auto simulate = [&](const fs::path& file, const std::string& out) {
    return test::finish(test::start_program(t.cap(), "/usr/bin/env",
                                            {"PORTALSIM_KERNEL_PROGRAM=" + file.string(), portalsim::test::kBinary,
                                             "simulate", "gun", "--out", (t.w() / out).string()}));
  };
  const test::Result same = simulate(t.w() / "same.cl", "same");
  EXPECT_TRUE(same.exited && same.status == 0) << test::describe(same);
  const test::Result broken = simulate(t.w() / "broken.cl", "broken");
  EXPECT_TRUE(broken.exited && broken.status != 0) << test::describe(broken);
  EXPECT_NE(broken.err.find("OpenCL program build failed"), std::string::npos) << broken.err;
  const test::Result missing = simulate(t.w() / "missing.cl", "missing");
  EXPECT_TRUE(missing.exited && missing.status == 5) << test::describe(missing);
  EXPECT_NE(missing.err.find("PORTALSIM_KERNEL_PROGRAM=" + (t.w() / "missing.cl").string()), std::string::npos)
      << missing.err;
  EXPECT_FALSE(fs::exists(t.w() / "broken") || fs::exists(t.w() / "missing"));
}

}  // namespace
}  // namespace portalsim
