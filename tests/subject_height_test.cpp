// Subject height (catalogue key `height`, procedural::Body::height): the drawn body scales
// about the floor, object places follow it in both backends, the annotations and the
// metal detector's physics model, and bad values are refused with file, line and field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "assets/procedural.h"
#include "backend/annotate.h"
#include "backend/compare.h"
#include "base/error.h"
#include "plan/tolerance.h"
#include "support.h"

namespace portalsim {
namespace {

// The default catalogue with `line` added to subject k's table (support.h).
std::string with_subject_line(int k, const std::string& line, int* at = nullptr) {
  return test::with_subject_line(test::default_catalogue_text(), k, line, at);
}

// The default catalogue with each subject's height given (1.0 for subjects not listed).
Catalogue heights_catalogue(const std::vector<double>& heights) {
  std::string t = test::default_catalogue_text();
  for (size_t j = 0; j < heights.size(); ++j) {
    std::ostringstream line;
    line << "height = " << heights[j];
    t = test::with_subject_line(t, static_cast<int>(j), line.str());
  }
  return parse_catalogue(t, "heights.toml", std::string(PORTALSIM_SOURCE_DIR) + "/scenarios");
}

// What the catalogue `text`, read as h.toml, is refused with; empty when it is accepted.
std::string error_of(const std::string& text) { return test::catalogue_error(text, "h.toml"); }

TEST(SubjectHeight, CatalogueReadsHeightAndRefusesBadValues) {
  for (const Subject& s : test::catalogue().subjects) EXPECT_EQ(s.shape.height, 1.0) << s.name << ": the default";
  EXPECT_EQ(parse_catalogue(with_subject_line(1, "height = 1.1"), "h.toml", "").subjects[1].shape.height, 1.1);
  EXPECT_EQ(parse_catalogue(with_subject_line(0, "height = 0.85"), "h.toml", "").subjects[0].shape.height, 0.85);
  struct Bad {
    std::string value, says;
  };
  for (const Bad& b :
       {Bad{"nan", "must be a finite number"}, Bad{"inf", "must be a finite number"},
        Bad{"1.3", "out of range [0.85, 1.15]"}, Bad{"0.5", "out of range [0.85, 1.15]"}, Bad{"-1", "out of range"},
        Bad{"\"tall\"", "expected a number"}, Bad{"[1.0]", "expected a number"}, Bad{"true", "expected a number"}}) {
    int line = 0;
    const std::string e = error_of(with_subject_line(2, "height = " + b.value, &line));
    EXPECT_NE(e.find("h.toml:" + std::to_string(line) + ": subjects[3].height: "), std::string::npos)
        << b.value << ": " << e;
    EXPECT_NE(e.find(b.says), std::string::npos) << b.value << ": " << e;
  }
  // A NUL byte inside the value, or after it in a comment: refused, naming the line.
  for (const std::string& v : {std::string("1.0\0"
                                           "5",
                                           5),
                               std::string("1.0 # \0", 7), std::string("\"1\0\"", 4)}) {
    int line = 0;
    const std::string e = error_of(with_subject_line(0, "height = " + v, &line));
    EXPECT_NE(e.find("h.toml:" + std::to_string(line)), std::string::npos) << e;
  }
  // A body from image files cannot be drawn at another height.
  int line = 0;
  const std::string e = error_of(with_subject_line(0, "height = 1.1\nimages.upper = \"u.png\"", &line));
  EXPECT_NE(e.find("h.toml:" + std::to_string(line) + ": subjects[1].height: only a procedural body"),
            std::string::npos)
      << e;
  EXPECT_EQ(error_of(with_subject_line(0, "height = 1.0\nimages.upper = \"u.png\"")), "") << "height 1 is allowed";
}

// First and last row with a body pixel (above `threshold`) in columns [x0, x1].
std::pair<int, int> body_rows(const Image& im, int x0, int x1, int threshold) {
  int first = -1, last = -1;
  for (int y = 0; y < im.height; ++y)
    for (int x = x0; x <= x1; ++x)
      if (im.at(x, y) > threshold) {
        if (first < 0) first = y;
        last = y;
      }
  return {first, last};
}

// Row `row` of the body at height 1 in a view whose floor is `floor` rows below its top:
// drawn at height h at floor - (floor - row) h (pixel centres are at row + 0.5).
double moved(double row, double floor, double h) { return floor - (floor - (row + 0.5)) * h - 0.5; }

// The last body row of the hanging hand: upper MMW view columns 15..40, IR columns 5..20.
int hand_bottom_mmw(const Image& up) { return body_rows(up, 15, 40, 90).second; }
int hand_bottom_ir(const Image& ir) { return body_rows(ir, 5, 20, 100).second; }

TEST(SubjectHeight, DrawnBodyScalesAboutTheFloor) {
  using procedural::Body;
  const Body one;
  const Image up1 = procedural::mmw_body(one, true, 200, 200), low1 = procedural::mmw_body(one, false, 200, 200),
              ir1 = procedural::ir_body(one, 100, 200);
  // The crotch: the last body row at the centre column from the top down to the gap
  // between the legs.
  const auto crotch = [](const Image& im) {
    int y = 0;
    while (y < im.height && im.at(100, y) > 90) ++y;
    return y - 1;
  };
  for (double h : {0.85, 0.9, 1.1, 1.15}) {
    SCOPED_TRACE("height " + std::to_string(h));
    Body b;
    b.shape.height = h;
    const Image up = procedural::mmw_body(b, true, 200, 200), low = procedural::mmw_body(b, false, 200, 200),
                ir = procedural::ir_body(b, 100, 200);
    // Upper view (floor 400 rows below its top). Shorter: the shoulders' top (columns
    // beside the neck) moves down; taller: it leaves the view, and the hands' lowest row
    // (which leaves it for a shorter body) moves up.
    if (h < 1) {
      const int sh1 = body_rows(up1, 55, 62, 90).first, sh = body_rows(up, 55, 62, 90).first;
      EXPECT_NEAR(sh, moved(sh1, 400, h), 1.5);
      EXPECT_GT(sh - sh1, 20) << "the shoulders really moved";
    } else {
      EXPECT_NEAR(hand_bottom_mmw(up), moved(hand_bottom_mmw(up1), 400, h), 1.5);
      EXPECT_LT(hand_bottom_mmw(up), hand_bottom_mmw(up1) - 15) << "the hands really moved";
    }
    // Lower view (floor at its bottom edge): the feet stay, the crotch moves.
    EXPECT_NEAR(body_rows(low, 60, 140, 90).second, body_rows(low1, 60, 140, 90).second, 1) << "feet on the floor";
    EXPECT_NEAR(crotch(low), moved(crotch(low1), 200, h), 1.5);
    // IR (the whole body at half scale, floor at the bottom): the hands move, the feet stay.
    EXPECT_NEAR(hand_bottom_ir(ir), moved(hand_bottom_ir(ir1), 200, h), 1.5);
    EXPECT_NEAR(body_rows(ir, 30, 70, 100).second, body_rows(ir1, 30, 70, 100).second, 1) << "feet on the floor";
  }
  EXPECT_EQ(procedural::mmw_body(Body{}, true, 200, 200).pixels, up1.pixels) << "height 1 draws today's body";
}

// The centre row of region r's annotation box in view k for a scenario holding `variant`
// alone in region r on subject 0.
double box_centre(const Catalogue& cat, const AssetSet& a, int k, int r, int variant) {
  Scenario s;
  s.subject = 0;
  s.objects[r] = static_cast<int16_t>(variant);
  std::vector<ViewAnnotations> out;
  annotate(cat, a, ModelSettings{}, test::batch_of({s}), out);
  const ViewAnnotations& va = out[k];
  EXPECT_EQ(va.first[1] - va.first[0], 1u) << "one object, one box";
  if (va.items.empty()) return -1;
  return va.items[0].y + (va.items[0].h - 1) / 2.0;
}

// An object in a region stays on the same body part: its box centre's height above the
// floor scales with the body's (the drawn shoulders' height above the floor).
TEST(SubjectHeight, ObjectsStayOnTheirBodyPart) {
  const Catalogue lo = heights_catalogue({0.9}), hi = heights_catalogue({1.1});
  const AssetSet alo = build_assets(lo), ahi = build_assets(hi);
  const int plate = test::variant_of(lo, "metal-plate");
  // The drawn body's own scale in IR: the hanging hand's lowest row.
  const int ir = lo.sensor_index("ir");
  const double llo = hand_bottom_ir(alo.bases[0][ir]), lhi = hand_bottom_ir(ahi.bases[0][ir]);
  // Region 8 (centre hip, 0-based 7) at 1.1 reaches above the lower view: cut off there,
  // as the body part is, and not drawn in the upper view (which sees regions 1-6 only).
  {
    const int low = lo.sensor_index("lower");
    Scenario s;
    s.objects[7] = static_cast<int16_t>(plate);
    std::vector<ViewAnnotations> out;
    annotate(hi, ahi, ModelSettings{}, test::batch_of({s}), out);
    ASSERT_EQ(out[low].items.size(), 1u);
    EXPECT_EQ(out[low].items[0].y, 0);
    EXPECT_LT(out[low].items[0].h, ahi.sprite(hi.sensors[low], plate).height);
  }
  for (int r : {1, 4, 8, 9, 11}) {
    SCOPED_TRACE("region " + std::to_string(r + 1));
    for (int k = 0; k < static_cast<int>(lo.sensors.size()); ++k) {
      const Sensor& s = lo.sensors[k];
      if (!s.sees(r)) continue;
      const double floor = s.floor_row;
      const double clo = box_centre(lo, alo, k, r, plate), chi = box_centre(hi, ahi, k, r, plate);
      // Height above the floor over the stature: the same body point (whole-pixel places).
      EXPECT_NEAR((floor - clo) / 0.9, (floor - chi) / 1.1, 1.5) << s.name;
      if (s.name == "ir") {
        // Against the drawn body: the same multiple of the hands' height above the floor
        // (a fixed place would be off by about 20%).
        EXPECT_NEAR((floor - clo) / (floor - llo), (floor - chi) / (floor - lhi), 0.03);
        if (r != 11) {
          EXPECT_GT(std::abs(clo - chi), 4) << "the places moved";
        }
      }
    }
  }
}

// Both backends within the standard tier's parity tolerance for non-unit heights, both
// models; the physics model's metal zones follow the moved places (and differ from
// height 1's), while the thesis model's per-region table does not change.
TEST(SubjectHeight, BothBackendsAgreeAndMetalFollows) {
  const Catalogue cat = heights_catalogue({0.86, 0.93, 1.0, 1.08, 1.15});
  const AssetSet a = build_assets(cat);
  const SceneBatch batch = test::batch_of(test::parity_set(cat, cat.variant_list.size() * kBuiltinRegions + 120, 8));
  auto ref = make_reference_backend(cat, a);
  auto cl = make_opencl_backend(cat, a, test::runtime());
  for (Model model : {Model::thesis, Model::physics}) {
    SCOPED_TRACE(model_name(model));
    Plan p = model == Model::physics ? test::physics_plan() : Plan{};
    BatchOutput r, k;
    ref->run(batch, p, r);
    cl->run(batch, p, k);
    const OutputDiff d = compare_outputs(k, r);
    if (model == Model::thesis) {
      EXPECT_EQ(check_tolerance(d, tier_tolerance(Tier::standard)), "");
    } else {  // the physics model's stated tolerance (physics_test.cpp)
      test::expect_camera_parity(d.of(Camera::mmw));
      EXPECT_LE(d.feature_max_abs, 1.0);
    }
    EXPECT_EQ(d.metal_exact, 1.0);
    // The same scenarios on subjects of height 1 (the default catalogue's bodies but for
    // the heights): the thesis model's metal is per region, the same; the physics
    // model's coil signals see the moved objects.
    const Catalogue& flat = test::catalogue();
    BatchOutput f;
    make_opencl_backend(flat, test::assets(), test::runtime())->run(batch, p, f);
    if (model == Model::thesis)
      EXPECT_EQ(f.metal, k.metal);
    else
      EXPECT_NE(f.metal, k.metal);
  }
  // Thesis features-only from the footprint tables (sparse) against the dense path, to
  // the bit: each subject's footprints sit at its places.
  // Features of plan `p` (sparse) and of the same plan pooled densely.
  const auto sparse_and_dense = [&](const Plan& p) {
    Plan dense = p;
    dense.fidelity.pooling = Pooling::dense;
    std::pair<BatchOutput, BatchOutput> o;
    cl->run(batch, p, o.first);
    cl->run(batch, dense, o.second);
    return o;
  };
  for (bool noise : {true, false}) {
    Plan p;
    p.images = 0;
    p.model.pattern_noise = noise;
    p.model.seed = 4242;
    ASSERT_EQ(test::features_path(*cl, p), "thesis_sparse_features");
    const auto [s, dn] = sparse_and_dense(p);
    EXPECT_EQ(s.features, dn.features) << "pattern noise " << noise;
  }
  // Physics features-only from the object tables (sparse) against the dense path: the
  // tables' pairs of meeting objects hold for every subject's places.
  Plan p = test::physics_plan();
  p.images = 0;
  p.metal = false;
  p.model.netd = 0;
  p.fidelity = tier_fidelity(Tier::fast);
  ASSERT_EQ(test::features_path(*cl, p), "physics_raw_features");
  const auto [s, dn] = sparse_and_dense(p);
  ASSERT_EQ(s.features.size(), dn.features.size());
  EXPECT_LE(compare_outputs(s, dn).feature_max_abs, 0.5);
}

// Height 1 moves nothing: every place is the region's rectangle.
TEST(SubjectHeight, UnitHeightPlacesAreTheRectangles) {
  const Catalogue& cat = test::catalogue();
  for (const Sensor& s : cat.sensors)
    for (size_t j = 0; j < cat.subjects.size(); ++j)
      for (int r = 0; r < kBuiltinRegions; ++r) {
        EXPECT_EQ(s.place(static_cast<int>(j), r).y, s.rects[r].y);
        EXPECT_EQ(s.place(static_cast<int>(j), r).x, s.rects[r].x);
      }
  const Catalogue hi = heights_catalogue({1.15});
  // Region 1 (right chest, centre row 75 of the upper view): 325 rows above the floor,
  // drawn 373.75 above it, 48.75 rows higher: 49 whole pixels.
  EXPECT_EQ(hi.sensors[0].subject_dy[0][0], -49);
  EXPECT_EQ(hi.sensors[0].subject_dy[1][0], 0);
}

}  // namespace
}  // namespace portalsim
