// Stages as units: every registered stage has a reference function and a kernel; each
// stage kernel agrees with its reference when it runs alone between composite and
// display; and the fused render_view (a declared fast path) gives the same bits as the
// chain of stage kernels in every tier.
//
// Tolerances, per stage against its reference (standard tier, fp32 against fp64):
//   pixels within 1 gray level (x.5 rounding ties), under 0.1% of pixels differing.
// Fused against staged kernels: identical bits, every tier.
#include "backend/stages.h"

#include <gtest/gtest.h>

#include "backend/compare.h"
#include "backend/opencl/kernels.h"
#include "plan/tolerance.h"
#include "support.h"

namespace portalsim {
namespace {

using test::assets;
using test::catalogue;

std::vector<Scenario> scenes(size_t n, int max_objects = 6) {
  std::vector<Scenario> v;
  for (size_t k = 0; k < n; ++k) v.push_back(test::random_scenario(catalogue(), k, max_objects));
  return v;
}

TEST(Stages, EveryStageHasAReferenceAndAKernel) {
  ASSERT_GE(view_stages().size(), 4u);
  cl::Program& program =
      test::runtime()->program(opencl::build_options(Fidelity{}, opencl::KernelCounts::of(catalogue())));
  for (const ViewStage& s : view_stages()) {
    SCOPED_TRACE(std::string(s.name));
    EXPECT_NE(s.reference, nullptr);
    ASSERT_FALSE(s.kernels.empty());
    for (const StageKernel& k : s.kernels) EXPECT_NO_THROW(cl::Kernel(program, std::string(k.kernel).c_str()));
    EXPECT_EQ(&view_stage(s.name), &s);
  }
  EXPECT_THROW(view_stage("no_such_stage"), std::invalid_argument);
  Sensor broken = catalogue().sensors[0];
  broken.chain = {"composite"};
  EXPECT_THROW(check_chain(broken), std::logic_error) << "a chain without display makes no pixels";
  broken.chain = {"composite", "blur", "display"};
  EXPECT_THROW(check_chain(broken), std::invalid_argument);
  broken = catalogue().sensors[0];
  broken.physics_chain = {"radiometry", "mmw_display", "optics"};
  EXPECT_THROW(check_chain(broken), std::logic_error) << "only the last stage makes pixels";
  // Every chain a sensor names is registered.
  for (const Sensor& sensor : catalogue().sensors)
    for (Model m : {Model::thesis, Model::physics})
      for (const std::string& name : sensor.chain_for(m)) EXPECT_NO_THROW(view_stage(name)) << sensor.name;
}

// The fast path is tested against the chain of per-stage kernels: same bits.
TEST(Stages, FusedRenderEqualsTheChainOfStageKernels) {
  auto cl = make_opencl_backend(catalogue(), assets(), test::runtime());
  const SceneBatch batch = test::batch_of(scenes(96));
  struct Case {
    const char* name;
    Tier tier;
    double sigma, jitter;
    bool bilinear;
    bool box_muller = false;  // the fast tier with the standard tier's draws
    bool irwin_hall = false;  // fp32 and fp64 with the fast tier's draws
  };
  for (const Case& c :
       {Case{"standard", Tier::standard, 0, 0, false}, Case{"standard noisy", Tier::standard, 2.5, 0, false},
        Case{"exact jitter", Tier::exact, 1.5, 3, false}, Case{"fast bilinear", Tier::fast, 2, 2.5, true},
        Case{"standard bilinear", Tier::standard, 0, 4, true}, Case{"fast", Tier::fast, 0, 0, false},
        Case{"fast noisy", Tier::fast, 2, 0, false},
        // Sprites and tiles moved across the image edges: spans clipped at both ends of
        // rows, and runs of noisy pixels that cross a row end with layers on both rows.
        Case{"standard over the edges", Tier::standard, 0, 60, false},
        Case{"standard noisy over the edges", Tier::standard, 2, 60, false},
        Case{"fast noisy over the edges", Tier::fast, 3, 60, false},
        Case{"fast noisy, Box-Muller", Tier::fast, 2, 0, false, true},
        Case{"standard noisy, Irwin-Hall", Tier::standard, 2, 0, false, false, true},
        Case{"exact noisy, Irwin-Hall", Tier::exact, 2, 0, false, false, true}}) {
    SCOPED_TRACE(c.name);
    Plan plan;
    plan.model.seed = 11;
    plan.model.pixel_sigma = c.sigma;
    plan.model.jitter = c.jitter;
    plan.model.bilinear = c.bilinear;
    plan.fidelity = tier_fidelity(c.tier);
    plan.fidelity.pooling = Pooling::dense;
    if (c.box_muller) plan.fidelity.draw = NoiseDraw::box_muller;
    if (c.irwin_hall) plan.fidelity.draw = NoiseDraw::irwin_hall;
    BatchOutput fused, staged;
    cl->run(batch, plan, fused);
    plan.fidelity.fused = false;
    cl->run(batch, plan, staged);
    ASSERT_EQ(fused.views.size(), staged.views.size());
    for (size_t k = 0; k < fused.views.size(); ++k) {
      ASSERT_FALSE(fused.views[k].empty());
      EXPECT_EQ(fused.views[k].pixels, staged.views[k].pixels) << fused.views[k].name;
    }
    EXPECT_EQ(fused.features, staged.features);
    EXPECT_EQ(fused.metal, staged.metal);
  }
}

// Each stage alone between composite and display, kernel against reference.
TEST(Stages, EachStageKernelMatchesItsReference) {
  const SceneBatch batch = test::batch_of(scenes(64));
  for (const ViewStage& stage : view_stages()) {
    if (stage.name == "composite" || stage.name == "display") continue;  // in every chain below
    // The thesis chain's stages; the physics model's are tested in physics_test.cpp.
    const std::vector<std::string>& thesis = catalogue().sensors[0].chain;
    if (std::find(thesis.begin(), thesis.end(), stage.name) == thesis.end()) continue;
    SCOPED_TRACE(std::string(stage.name));
    Catalogue cat = catalogue();
    for (Sensor& s : cat.sensors) s.chain = {"composite", std::string(stage.name), "display"};
    const AssetSet& a = assets();
    auto ref = make_reference_backend(cat, a);
    auto cl = make_opencl_backend(cat, a, test::runtime());
    Plan plan;
    plan.model.seed = 5;
    plan.model.pixel_sigma = 3;
    plan.fidelity.fused = false;
    BatchOutput r, k;
    // Sensor noise under both pixel draws (the reference follows the plan's).
    for (NoiseDraw draw : {NoiseDraw::irwin_hall, NoiseDraw::box_muller}) {
      if (stage.name != "sensor_noise" && draw == NoiseDraw::irwin_hall) continue;
      SCOPED_TRACE(draw == NoiseDraw::irwin_hall ? "irwin-hall" : "box-muller");
      plan.fidelity.draw = draw;
      ref->run(batch, plan, r);
      cl->run(batch, plan, k);
      const OutputDiff d = compare_outputs(k, r);
      EXPECT_LE(d.of(Camera::mmw).max_abs, 1);
      EXPECT_LE(d.of(Camera::ir).max_abs, 1);
      EXPECT_LE(d.of(Camera::mmw).share_differing, 1e-3);
      EXPECT_LE(d.of(Camera::ir).share_differing, 1e-3);
    }
    // The stage did something: without it the images differ.
    Catalogue bare = catalogue();
    for (Sensor& s : bare.sensors) s.chain = {"composite", "display"};
    auto plain = make_reference_backend(bare, a);
    BatchOutput p;
    plain->run(batch, plan, p);
    EXPECT_NE(p.view("upper").pixels, r.view("upper").pixels) << "the stage changes nothing: the test cannot fail";
  }
}

// The chain is what a sensor lists: dropping a stage from the descriptor drops it from
// both backends.
TEST(Stages, TheSensorsChainDecidesWhatRuns) {
  Catalogue cat = catalogue();
  const int ir = cat.sensor_index("ir");
  ASSERT_GE(ir, 0);
  cat.sensors[ir].chain = {"composite", "display"};
  const AssetSet& a = assets();
  Plan plan;
  plan.model.pixel_sigma = 4;
  plan.fidelity.fused = false;
  const SceneBatch batch = test::batch_of(scenes(8));
  std::vector<std::unique_ptr<Backend>> backends;
  backends.push_back(make_reference_backend(cat, a));
  backends.push_back(make_opencl_backend(cat, a, test::runtime()));
  for (auto& backend : backends) {
    BatchOutput noisy, quiet;
    backend->run(batch, plan, noisy);
    Plan off = plan;
    off.model.pixel_sigma = 0;
    backend->run(batch, off, quiet);
    EXPECT_EQ(noisy.view("ir").pixels, quiet.view("ir").pixels) << backend->name() << ": IR has no sensor noise stage";
    EXPECT_NE(noisy.view("upper").pixels, quiet.view("upper").pixels) << backend->name();
  }
}

}  // namespace
}  // namespace portalsim
