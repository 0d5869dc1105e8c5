// Randomised objects (--rotate, --scale, --flip; README "Randomised objects"): the kernels'
// affine sampling against the fp64 reference in every tier, determinism, a flip that is a
// real mirror, the identity knobs giving today's output, the dense path for features,
// scenarios.csv recording the draws and re-making the images, and bad values refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>

#include "backend/compare.h"
#include "backend/reference/stages.h"
#include "base/error.h"
#include "plan/knobs.h"
#include "plan/tolerance.h"
#include "run_binary.h"
#include "scene/generator.h"
#include "scene/scenario_list.h"
#include "support.h"

namespace portalsim {
namespace {

void randomise(Plan& p, double rotate = 45, double scale_lo = 0.6, double scale_hi = 1.6, bool flip = true) {
  p.model.rotate_lo = -rotate;
  p.model.rotate_hi = rotate;
  p.model.scale_lo = scale_lo;
  p.model.scale_hi = scale_hi;
  p.model.flip = flip;
}

std::vector<Scenario> scenes(uint64_t n, int max_objects = 6, uint64_t first = 0) {
  std::vector<Scenario> s;
  for (uint64_t k = first; k < first + n; ++k) s.push_back(test::random_scenario(test::catalogue(), k, max_objects));
  return s;
}

// Every tier's kernels within its stated tolerance of the reference, with objects turned,
// scaled and mirrored, at integer and sub-pixel placement, with jitter and noise; and
// the transforms really change the images.
TEST(RandomisedObjects, KernelsMatchTheReferenceInEveryTier) {
  const std::vector<Scenario> sc = scenes(120);
  auto cl = make_opencl_backend(test::catalogue(), test::assets(), test::runtime());
  auto ref = make_reference_backend(test::catalogue(), test::assets());
  for (const Tier tier : {Tier::exact, Tier::standard, Tier::fast})
    for (const bool bilinear : {false, true}) {
      SCOPED_TRACE(std::string(tier_name(tier)) + (bilinear ? " bilinear" : " integer"));
      Plan p;
      p.fidelity = tier_fidelity(tier);
      p.model.seed = 17;
      p.model.bilinear = bilinear;
      p.model.jitter = 3.5;
      BatchOutput still;
      cl->run(test::batch_of(sc), p, still);
      randomise(p);
      ASSERT_NE(test::features_path(*cl, p), "thesis_sparse_features")
          << "the sparse path cannot follow random transforms";
      BatchOutput a, b;
      cl->run(test::batch_of(sc), p, a);
      ref->run(test::batch_of(sc), p, b);
      const OutputDiff d = compare_outputs(a, b);
      EXPECT_EQ(check_tolerance(d, tier_tolerance(tier)), "");
      EXPECT_GT(compare_outputs(a, still).of(Camera::mmw).max_abs, 50) << "the transforms must change the images";
      EXPECT_EQ(a.metal, still.metal) << "transforms leave the metal detector as it was";
    }
}

// The built-in sprites fade to no coverage at their edges, so a turned sprite's box (the
// pixels its inverse map is sampled on) could be a little short and nothing would show. With
// every sprite opaque to its edge, the bilinear fringe past the last texel counts: a box
// half a pixel short (mutation 39 of tools/mutations.txt) misses it.
TEST(RandomisedObjects, OpaqueSpriteEdgesMatchTheReference) {
  AssetSet opaque = test::assets();
  for (auto& camera : opaque.sprites)
    for (Image& s : camera)
      for (size_t k = size_t(s.channels) - 1; k < s.pixels.size(); k += size_t(s.channels)) s.pixels[k] = 255;
  const std::vector<Scenario> sc = scenes(120);
  auto cl = make_opencl_backend(test::catalogue(), opaque, test::runtime());
  auto ref = make_reference_backend(test::catalogue(), opaque);
  for (const bool fused : {true, false})
    for (const bool bilinear : {false, true}) {
      SCOPED_TRACE(std::string(fused ? "fused" : "stage chain") + (bilinear ? ", bilinear" : ", integer"));
      Plan p;
      p.model.seed = 23;
      p.model.bilinear = bilinear;
      p.fidelity.fused = fused;
      randomise(p);
      BatchOutput a, b, builtin;
      cl->run(test::batch_of(sc), p, a);
      ref->run(test::batch_of(sc), p, b);
      EXPECT_EQ(check_tolerance(compare_outputs(a, b), tier_tolerance(Tier::standard)), "");
      make_opencl_backend(test::catalogue(), test::assets(), test::runtime())->run(test::batch_of(sc), p, builtin);
      EXPECT_NE(a.view("upper").pixels, builtin.view("upper").pixels) << "the opaque sprites must be used";
    }
}

// The physics model's chains (radiometry, contact shadow, the fused raw-grid path) sample
// the same transformed sprites, within the model's tolerance.
TEST(RandomisedObjects, PhysicsModelKernelsMatchTheReference) {
  const std::vector<Scenario> sc = scenes(60);
  auto cl = make_opencl_backend(test::catalogue(), test::assets(), test::runtime());
  auto ref = make_reference_backend(test::catalogue(), test::assets());
  for (const bool fused : {true, false}) {
    Plan p = test::physics_plan(5);
    p.fidelity.fused = fused;
    randomise(p, 90, 0.5, 1.5);
    BatchOutput a, b;
    cl->run(test::batch_of(sc), p, a);
    ref->run(test::batch_of(sc), p, b);
    EXPECT_EQ(check_tolerance(compare_outputs(a, b), model_tolerance(Model::physics, Tier::standard)), "")
        << "fused " << fused;
  }
}

// Scenario i's images depend on (seed, i) only: batches of any size give the same bytes.
TEST(RandomisedObjects, SameBytesForAnyBatchSplit) {
  const std::vector<Scenario> sc = scenes(45, 13);
  auto cl = make_opencl_backend(test::catalogue(), test::assets(), test::runtime());
  Plan p;
  p.model.seed = 8;
  p.model.pixel_sigma = 2;
  randomise(p, 180, 0.3, 3);
  BatchOutput whole;
  cl->run(test::batch_of(sc, 1000), p, whole);
  for (const size_t step : {1, 7, 32}) {
    BatchOutput all, part;
    for (size_t i = 0; i < sc.size(); i += step) {
      const std::vector<Scenario> piece(sc.begin() + i, sc.begin() + std::min(sc.size(), i + step));
      cl->run(test::batch_of(piece, 1000 + i), p, part);
      if (i == 0)
        all = part;
      else
        append_output(all, part);
    }
    for (size_t k = 0; k < whole.views.size(); ++k)
      EXPECT_EQ(all.views[k].pixels, whole.views[k].pixels) << "batches of " << step << " view " << k;
  }
}

// The assets with every sprite mirrored left to right.
AssetSet mirrored_sprites() {
  AssetSet a = test::assets();
  for (auto& camera : a.sprites)
    for (Image& s : camera) {
      const Image o = s;
      for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x)
          for (int c = 0; c < s.channels; ++c) s.at(x, y, c) = o.at(s.width - 1 - x, y, c);
    }
  return a;
}

// --flip on alone mirrors an object exactly when its draw says so: its images equal, bit
// for bit, those of the mirrored sprite drawn unflipped (sampling falls on whole texels),
// in both backends; otherwise they equal the plain sprite's.
TEST(RandomisedObjects, FlipIsARealMirror) {
  const Catalogue& cat = test::catalogue();
  const AssetSet mirrored = mirrored_sprites();
  std::vector<Scenario> sc;
  for (uint64_t k = 0; k < 48; ++k) {
    Scenario s;
    const Philox4 q = draw(99, k, 7, 0);
    s.subject = static_cast<int>(below(q[0], static_cast<uint32_t>(cat.subjects.size())));
    s.objects[below(q[1], kBuiltinRegions)] =
        static_cast<int16_t>(below(q[2], static_cast<uint32_t>(cat.variant_list.size())));
    sc.push_back(s);
  }
  Plan flip;
  flip.model.seed = 4;
  flip.model.flip = true;
  Plan plain = flip;
  plain.model.flip = false;
  plain.model.bilinear = true;  // the same per-pixel sampling, unturned
  const std::vector<std::pair<std::unique_ptr<Backend>, std::unique_ptr<Backend>>> backends = [&] {
    std::vector<std::pair<std::unique_ptr<Backend>, std::unique_ptr<Backend>>> b;
    b.emplace_back(make_reference_backend(cat, test::assets()), make_reference_backend(cat, mirrored));
    b.emplace_back(make_opencl_backend(cat, test::assets(), test::runtime()),
                   make_opencl_backend(cat, mirrored, test::runtime()));
    return b;
  }();
  for (const auto& [normal, mirror] : backends) {
    BatchOutput f, m, n;
    normal->run(test::batch_of(sc), flip, f);
    mirror->run(test::batch_of(sc), plain, m);
    normal->run(test::batch_of(sc), plain, n);
    int flipped = 0, kept = 0;
    for (size_t i = 0; i < sc.size(); ++i) {
      int region = 0;
      while (sc[i].objects[region] == kNoObject) ++region;
      const bool mirrored_draw = object_transform(flip.model, i, region).flip;
      (mirrored_draw ? flipped : kept) += 1;
      const BatchOutput& want = mirrored_draw ? m : n;
      for (size_t k = 0; k < f.views.size(); ++k) {
        const size_t px = f.views[k].pixels_per_image();
        EXPECT_TRUE(std::equal(f.views[k].of(i), f.views[k].of(i) + px, want.views[k].of(i)))
            << normal->name() << " scenario " << i << " view " << f.views[k].name << " flipped " << mirrored_draw;
      }
    }
    EXPECT_GT(flipped, 10);
    EXPECT_GT(kept, 10);
  }
}

// --rotate 0, --scale 1..1 and --flip off are today's model: the same bytes as a plan
// that never heard of the knobs.
TEST(RandomisedObjects, IdentityKnobsGiveTodaysOutput) {
  auto cl = make_opencl_backend(test::catalogue(), test::assets(), test::runtime());
  const std::vector<Scenario> sc = scenes(30, 13);
  for (const bool bilinear : {false, true}) {
    Plan today;
    today.model.seed = 3;
    today.model.jitter = 2.5;
    today.model.bilinear = bilinear;
    Plan knobs = today;
    set_knob(knobs, *find_knob("rotate"), "0", "--rotate");
    set_knob(knobs, *find_knob("scale"), "1..1", "--scale");
    set_knob(knobs, *find_knob("flip"), "off", "--flip");
    EXPECT_FALSE(knobs.model.transforms());
    BatchOutput a, b;
    cl->run(test::batch_of(sc), today, a);
    cl->run(test::batch_of(sc), knobs, b);
    for (size_t k = 0; k < a.views.size(); ++k) EXPECT_EQ(a.views[k].pixels, b.views[k].pixels);
    EXPECT_EQ(a.features, b.features);
    EXPECT_EQ(a.metal, b.metal);
  }
}

// Features-only runs with transforms take the dense path (render, then pool): they equal
// the features of a run that keeps the images, and the reference's pooling of those images.
TEST(RandomisedObjects, FeaturesAreThePooledImages) {
  const Catalogue& cat = test::catalogue();
  auto cl = make_opencl_backend(cat, test::assets(), test::runtime());
  const std::vector<Scenario> sc = scenes(40, 8);
  Plan p;
  p.model.seed = 21;
  randomise(p, 30, 0.8, 1.4);
  p.images = 0;
  ASSERT_EQ(test::features_path(*cl, p), Backend::kPooledFeatures);
  BatchOutput only, with_images;
  cl->run(test::batch_of(sc), p, only);
  p.images = kAllViews;
  cl->run(test::batch_of(sc), p, with_images);
  EXPECT_EQ(only.features, with_images.features);
  const FeatureLayout& layout = with_images.layout;
  std::vector<float> row(layout.image_features() + kBuiltinZones);
  double worst = 0;
  for (size_t i = 0; i < sc.size(); ++i) {
    std::vector<std::vector<uint8_t>> views(cat.sensors.size());
    for (size_t k = 0; k < cat.sensors.size(); ++k) {
      const ViewImages& v = with_images.views[k];
      views[k].assign(v.of(i), v.of(i) + v.pixels_per_image());
    }
    reference::pool(cat, views, layout, row.data());
    for (int f = 0; f < layout.image_features(); ++f)
      worst = std::max(worst, std::abs(double(row[f]) - only.features_of(i)[f]));
  }
  EXPECT_LE(worst, 1e-4) << "features against the pooled images (float sums)";
}

// An object's drawn transform: in its ranges, the same in every view, varying.
TEST(RandomisedObjects, DrawsLieInTheirRanges) {
  ModelSettings m;
  m.seed = 77;
  m.rotate_lo = -10;
  m.rotate_hi = 25;
  m.scale_lo = 0.5;
  m.scale_hi = 2;
  m.flip = true;
  double rlo = 1e9, rhi = -1e9, slo = 1e9, shi = -1e9;
  int flips = 0;
  for (uint64_t i = 0; i < 500; ++i)
    for (int r = 0; r < kBuiltinRegions; ++r) {
      const ObjectTransform t = object_transform(m, i, r);
      rlo = std::min(rlo, t.rotation), rhi = std::max(rhi, t.rotation);
      slo = std::min(slo, t.scale), shi = std::max(shi, t.scale);
      flips += t.flip;
    }
  EXPECT_GE(rlo, -10);
  EXPECT_LT(rhi, 25);
  EXPECT_LT(rlo, -9.5);
  EXPECT_GT(rhi, 24.5);
  EXPECT_GE(slo, 0.5);
  EXPECT_LT(shi, 2);
  EXPECT_NEAR(flips, 500 * kBuiltinRegions / 2, 200);
  m.flip = false;
  m.rotate_lo = m.rotate_hi = 0;
  m.scale_lo = m.scale_hi = 1;
  EXPECT_EQ(object_transform(m, 3, 4), ObjectTransform{});
}

using test::describe;
using test::finish;
using test::slurp;
using test::start;
using test::TempDir;

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> f;
  size_t a = 0;
  for (size_t b; (b = line.find(',', a)) != std::string::npos; a = b + 1) f.push_back(line.substr(a, b - a));
  f.push_back(line.substr(a));
  return f;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> l;
  size_t a = 0;
  for (size_t b; (b = text.find('\n', a)) != std::string::npos; a = b + 1) l.push_back(text.substr(a, b - a));
  return l;
}

// scenarios.csv records each object's rotation, scale and flip exactly (the draws of
// object_transform); `generate --scenarios` with the same seed and knobs re-makes the
// images byte for byte, any --batch and --threads give the same bytes, and another seed
// is refused, naming the file, line and region.
TEST(RandomisedObjects, ScenariosCsvRecordsTheDrawsAndRemakesTheImages) {
  TempDir t;
  const std::vector<std::string> knobs = {"--seed",   "6",      "--rotate", "-20..35", "--scale",
                                          "0.7..1.3", "--flip", "on",       "--what",  "images"};
  const auto gen = [&](const std::string& out, std::vector<std::string> extra) {
    std::vector<std::string> args = {"generate", "--out", (t.w() / out).string()};
    args.insert(args.end(), knobs.begin(), knobs.end());
    args.insert(args.end(), extra.begin(), extra.end());
    return finish(start(t.cap(), args));
  };
  test::Result r = gen("a", {"--count", "24", "--objects", "3..6", "--batch", "5", "--threads", "1"});
  ASSERT_TRUE(r.exited && r.status == 0) << describe(r);
  r = gen("b", {"--count", "24", "--objects", "3..6", "--batch", "64", "--threads", "2"});
  ASSERT_TRUE(r.exited && r.status == 0) << describe(r);
  r = gen("c", {"--scenarios", (t.w() / "a" / "scenarios.csv").string()});
  ASSERT_TRUE(r.exited && r.status == 0) << describe(r);

  const std::vector<std::string> rows = lines(slurp(t.w() / "a" / "scenarios.csv"));
  ASSERT_EQ(rows.size(), 25u);
  const std::vector<std::string> head = fields(rows[0]);
  ASSERT_EQ(head.size(), 2u + 4 * kBuiltinRegions + 1);
  EXPECT_EQ(head[2 + kBuiltinRegions], "rotation1");
  EXPECT_EQ(head[2 + 2 * kBuiltinRegions], "scale1");
  EXPECT_EQ(head[2 + 3 * kBuiltinRegions + 12], "flip13");
  Plan plan;
  for (const auto& [k, v] :
       std::vector<std::pair<std::string, std::string>>{{"rotate", "-20..35"}, {"scale", "0.7..1.3"}, {"flip", "on"}})
    set_knob(plan, *find_knob(k), v, k);
  plan.model.seed = 6;
  int objects = 0, flips = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    const std::vector<std::string> f = fields(rows[i]);
    ASSERT_EQ(f.size(), head.size());
    for (int r = 0; r < kBuiltinRegions; ++r) {
      const std::string &rot = f[2 + kBuiltinRegions + r], &sc = f[2 + 2 * kBuiltinRegions + r],
                        &fl = f[2 + 3 * kBuiltinRegions + r];
      if (f[2 + r] == "none") {
        EXPECT_TRUE(rot.empty() && sc.empty() && fl.empty());
        continue;
      }
      const ObjectTransform want = object_transform(plan.model, i - 1, r);
      double rv = 0, sv = 0;
      std::from_chars(rot.data(), rot.data() + rot.size(), rv);
      std::from_chars(sc.data(), sc.data() + sc.size(), sv);
      EXPECT_EQ(rv, want.rotation) << rows[i];
      EXPECT_EQ(sv, want.scale) << rows[i];
      EXPECT_EQ(fl, want.flip ? "1" : "0") << rows[i];
      EXPECT_TRUE(rv >= -20 && rv <= 35 && sv >= 0.7 && sv <= 1.3);
      ++objects;
      flips += want.flip;
    }
  }
  EXPECT_GT(objects, 60);
  EXPECT_GT(flips, 10);
  EXPECT_LT(flips, objects - 10);
  size_t compared = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(t.w() / "a" / "images")) {
    if (!e.is_regular_file()) continue;
    const auto rel = std::filesystem::relative(e.path(), t.w() / "a");
    const std::string bytes = slurp(e.path());
    EXPECT_EQ(bytes, slurp(t.w() / "b" / rel)) << rel << ": --batch and --threads must not matter";
    EXPECT_EQ(bytes, slurp(t.w() / "c" / rel)) << rel << ": re-made from scenarios.csv";
    ++compared;
  }
  EXPECT_GE(compared, 24u * 3);

  // Another seed draws other transforms: the recorded ones cannot be re-made, so it is refused.
  std::vector<std::string> args = {
      "generate", "--out", (t.w() / "d").string(), "--scenarios", (t.w() / "a" / "scenarios.csv").string(),
      "--seed",   "7"};
  args.insert(args.end(), knobs.begin() + 2, knobs.end());
  r = finish(start(t.cap(), args));
  EXPECT_TRUE(r.exited && r.status != 0) << describe(r);
  EXPECT_NE(r.err.find("scenarios.csv:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(": region"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(t.w() / "d" / "images")) << "nothing is written";
}

// Bad values name the flag (or the file and line) and say what is expected.
TEST(RandomisedObjects, BadValuesAreRefusedClearly) {
  TempDir t;
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--scale", "0..1"}, "--scale: \"0..1\" must be A..B with 0.1 <= A <= B <= 10"},
      {{"--scale", "2..1"}, "--scale: \"2..1\" must be A..B"},
      {{"--rotate", "abc"}, "--rotate: \"abc\" is not a number X (for -X..X) or a range A..B"},
      {{"--rotate", "200"}, "--rotate: \"200\" must be A..B with -180 <= A <= B <= 180"},
      {{"--rotate", "1..nan"}, "--rotate: \"1..nan\" must be A..B"},
      {{"--scale", "1..2..3"}, "--scale: \"1..2..3\" is not a range"},
      {{"--flip", "yes"}, "--flip: \"yes\" is not on or off"},
  };
  for (const auto& [flag, message] : cases) {
    std::vector<std::string> args = {"simulate", "gun", "--out", (t.w() / "x").string()};
    args.insert(args.end(), flag.begin(), flag.end());
    const test::Result r = finish(start(t.cap(), args));
    EXPECT_TRUE(r.exited && r.status != 0) << describe(r);
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(t.w() / "x"));
  }
  // A scenario list with part of the transform columns, or a bad value in one.
  const std::string head = [] {
    std::string h = "subject";
    for (int r = 1; r <= kBuiltinRegions; ++r) h += ",region" + std::to_string(r);
    return h;
  }();
  const std::string nones = ",none,none,none,none,none,none,none,none,none,none,none,none";
  EXPECT_THROW(
      {
        try {
          parse_scenario_list(test::catalogue(), head + ",rotation1\n1,gun" + nones + ",5\n", "l.csv");
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("l.csv:1: header: the randomised objects' columns come together"),
                    std::string::npos)
              << e.what();
          throw;
        }
      },
      InputError);
  std::string full = head;
  for (const char* w : {",rotation", ",scale", ",flip"})
    for (int r = 1; r <= kBuiltinRegions; ++r) full += w + std::to_string(r);
  const std::string empties(12, ',');
  const auto row = [&](const std::string& rot, const std::string& sc, const std::string& fl) {
    return full + "\n1,gun" + nones + "," + rot + empties + "," + sc + empties + "," + fl + empties + "\n";
  };
  std::vector<ListedTransforms> got;
  parse_scenario_list(test::catalogue(), row("12.5", "1.25", "1"), "l.csv", &got);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].t[0], (ObjectTransform{12.5, 1.25, true}));
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {row("x", "1", "0"), "l.csv:2: region1 rotation: \"x\" is not a number"},
           {row("1", "", "0"), "l.csv:2: region1 scale: \"\" is not a number"},
           {row("1", "1", "2"), "l.csv:2: region1 flip: \"2\" is not 0 or 1"}}) {
    try {
      parse_scenario_list(test::catalogue(), text, "l.csv");
      ADD_FAILURE() << "accepted: " << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace portalsim
