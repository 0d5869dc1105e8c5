// Boxes and instance masks (backend/annotate.h) against pixels: each object rendered
// alone by the reference's composite (and by the kernels) over a black base with white
// sprites shows where it lands; the top-most one in region order owns a pixel.
#include <gtest/gtest.h>

#include <algorithm>

#include "backend/annotate.h"
#include "backend/reference/stages.h"
#include "support.h"

namespace portalsim {
namespace {

// The default assets with every base black and every sprite white (coverage kept), so a
// composited pixel is > 0 exactly where some sprite has coverage > 0.
AssetSet white_on_black() {
  AssetSet a = test::assets();
  for (auto& subject : a.bases)
    for (Image& b : subject) std::fill(b.pixels.begin(), b.pixels.end(), 0);
  for (auto& camera : a.sprites)
    for (Image& s : camera)
      for (size_t p = 0; p < s.pixels.size(); p += 2) s.pixels[p] = 255;
  return a;
}

struct Expected {
  std::vector<uint8_t> mask;
  int cut_off = 0, outside = 0;
};

// The mask from the reference's own composite: object k alone covers the pixels it
// makes > 0; the highest region covering a pixel owns it. count_edges: also count the
// objects cut off by the view's edge and outside it (most of the time, on a wide field).
Expected expected_mask(const AssetSet& a, const ModelSettings& m, int view, const Scenario& s, uint64_t index,
                       bool count_edges = true) {
  const Catalogue& cat = test::catalogue();
  const reference::ViewScene vs = reference::view_scene(cat, a, m, view, s, index);
  const Sensor& sensor = cat.sensors[view];
  Expected e;
  e.mask.assign(static_cast<size_t>(sensor.width) * sensor.height, 0);
  size_t p = 0;
  for (int r = 0; r < kBuiltinRegions; ++r) {
    if (s.objects[r] == kNoObject || !sensor.sees(r)) continue;
    reference::ViewScene alone = vs;
    alone.placed = {vs.placed[p++]};
    reference::Field f;
    reference::composite(alone, f);
    int covered = 0;
    for (size_t i = 0; i < f.v.size(); ++i)
      if (f.v[i] > 0) {
        e.mask[i] = static_cast<uint8_t>(r + 1);
        ++covered;
      }
    if (!count_edges) continue;
    // What the object covers at this placement as if the view had no edges: drawn alone
    // by the reference over a field with a wide margin round the view.
    constexpr int kMargin = 400;
    reference::ViewScene wide = alone;
    wide.placed[0].x0 += kMargin;
    wide.placed[0].y0 += kMargin;
    // One field for every call: a new one each time was most of this test's time under
    // the sanitizers (ASan maps every large block afresh, and the kernel pages it in).
    static reference::Field big;
    big.width = sensor.width + 2 * kMargin;
    big.height = sensor.height + 2 * kMargin;
    big.v.assign(static_cast<size_t>(big.width) * big.height, 0.0);
    reference::lay_objects(wide, big, cat.images.alpha,
                           [](const reference::ViewScene&, const reference::Placed& pl, int sx, int sy) {
                             return double(pl.sprite->at(sx, sy, 0));
                           });
    const auto whole = static_cast<int>(std::count_if(big.v.begin(), big.v.end(), [](double v) { return v > 0; }));
    if (covered == 0) ++e.outside;
    if (covered > 0 && covered < whole) ++e.cut_off;
  }
  return e;
}

TEST(Annotations, MasksAndBoxesAgreeWithTheReferenceComposite) {
  const Catalogue& cat = test::catalogue();
  const AssetSet a = white_on_black();
  int checked = 0;
  std::array<int, 2> occluded{}, cut_off{}, outside{};  // without and with randomised objects
  const uint64_t n = 40;
  for (const bool transforms : {false, true})
    for (const bool bilinear : {false, true})
      for (const double jitter : {0.0, 30.0, 140.0}) {
        ModelSettings m;
        m.seed = 5;
        m.bilinear = bilinear;
        m.jitter = jitter;
        if (transforms) {  // turned, scaled (down and up) and mirrored objects
          m.rotate_lo = -180;
          m.rotate_hi = 180;
          m.scale_lo = 0.5;
          m.scale_hi = 1.8;
          m.flip = true;
        }
        std::vector<Scenario> scenes;
        for (uint64_t k = 0; k < n; ++k) scenes.push_back(test::random_scenario(cat, k));
        const SceneBatch b = test::batch_of(scenes, 1000);
        std::vector<ViewAnnotations> got;
        annotate(cat, a, m, b, got, 2);
        ASSERT_EQ(got.size(), cat.sensors.size());
        for (size_t k = 0; k < cat.sensors.size(); ++k)
          for (size_t i = 0; i < scenes.size(); ++i) {
            const Expected e = expected_mask(a, m, static_cast<int>(k), scenes[i], 1000 + i);
            const ViewAnnotations& va = got[k];
            const size_t px = e.mask.size();
            ASSERT_TRUE(std::equal(e.mask.begin(), e.mask.end(), va.mask_of(i)))
                << "view " << cat.sensors[k].name << " scenario " << i << " bilinear " << bilinear << " jitter "
                << jitter << " transforms " << transforms;
            cut_off[transforms] += e.cut_off;
            outside[transforms] += e.outside;
            // Every region with a visible pixel has one annotation whose box and area are its pixels'.
            std::vector<int> seen(kBuiltinRegions + 1, 0);
            for (size_t p = 0; p < px; ++p) seen[e.mask[p]] = 1;
            int listed = 0;
            for (uint32_t t = va.first[i]; t < va.first[i + 1]; ++t) {
              const Annotation& x = va.items[t];
              ++listed;
              const int W = va.width;
              int x0 = W, y0 = va.height, x1 = -1, y1 = -1;
              uint32_t area = 0;
              for (size_t p = 0; p < px; ++p)
                if (e.mask[p] == x.region + 1) {
                  const int px_x = static_cast<int>(p % W), px_y = static_cast<int>(p / W);
                  x0 = std::min(x0, px_x), x1 = std::max(x1, px_x), y0 = std::min(y0, px_y), y1 = std::max(y1, px_y);
                  ++area;
                }
              EXPECT_EQ(x.area, area);
              EXPECT_EQ(x.x, x0);
              EXPECT_EQ(x.y, y0);
              EXPECT_EQ(x.w, x1 - x0 + 1);
              EXPECT_EQ(x.h, y1 - y0 + 1);
              const int16_t v = scenes[i].objects[x.region];
              ASSERT_NE(v, kNoObject);
              EXPECT_EQ(x.object, cat.variant_list[v].object);
              EXPECT_EQ(x.drawing, cat.variant_list[v].variant);
              // Covered by a later region: fewer pixels than when drawn alone.
              Scenario alone;
              alone.subject = scenes[i].subject;
              alone.objects[x.region] = v;
              const Expected solo = expected_mask(a, m, static_cast<int>(k), alone, 1000 + i, false);
              const auto solo_area =
                  static_cast<uint32_t>(std::count(solo.mask.begin(), solo.mask.end(), x.region + 1));
              EXPECT_LE(area, solo_area);
              occluded[transforms] += area < solo_area;
              if (transforms) {  // the attributes are the object's draw
                const ObjectTransform want = object_transform(m, 1000 + i, x.region);
                EXPECT_TRUE(x.rotation == want.rotation && x.scale == want.scale && x.flip == want.flip);
              } else {
                EXPECT_TRUE(x.rotation == 0 && x.scale == 1 && !x.flip);
              }
            }
            int regions_visible = 0;
            for (int r = 1; r <= kBuiltinRegions; ++r) regions_visible += seen[r];
            EXPECT_EQ(listed, regions_visible);
            ++checked;
          }
      }
  // The cases the test is for must have happened, with and without randomised objects.
  for (const int t : {0, 1}) {
    EXPECT_GT(occluded[t], 5) << "no object was covered by another; transforms " << t;
    EXPECT_GT(cut_off[t], 5) << "no object was cut off by the view's edge; transforms " << t;
    EXPECT_GT(outside[t], 5) << "no object fell outside its view; transforms " << t;
  }
  EXPECT_EQ(checked, 2 * 2 * 3 * static_cast<int>(n * cat.sensors.size()));
}

// annotate() clears a reused buffer only where it painted before, and an Annotator keeps
// its sprite tables, unmoved sprites' placements and workers' scratch masks between
// batches: batches of other sizes and scenes through one buffer and one Annotator must
// give what fresh ones give, with sprites that do not move (placed on the first such
// batch), that move, and again that do not, on one worker and on two (from 256 scenarios).
TEST(Annotations, ReusedBuffersGiveWhatFreshOnesGive) {
  const Catalogue& cat = test::catalogue();
  Annotator kept(cat, test::assets());
  for (const double jitter : {0.0, 20.0, 0.0}) {
    ModelSettings m;
    m.jitter = jitter;
    std::vector<ViewAnnotations> reused;
    size_t compared = 0;
    for (const auto& [first, n] :
         std::vector<std::pair<uint64_t, size_t>>{{0, 50}, {300, 20}, {900, 300}, {40, 70}, {2000, 260}}) {
      std::vector<Scenario> scenes;
      for (uint64_t k = 0; k < n; ++k) scenes.push_back(test::random_scenario(cat, first + k));
      const SceneBatch b = test::batch_of(scenes, first);
      std::vector<ViewAnnotations> fresh;
      annotate(cat, test::assets(), m, b, fresh, 1);
      kept(m, b, reused, 2);
      for (size_t k = 0; k < fresh.size(); ++k) {
        ASSERT_EQ(fresh[k].masks, reused[k].masks) << "batch at " << first << " view " << k << " jitter " << jitter;
        EXPECT_EQ(fresh[k].first, reused[k].first);
        ASSERT_EQ(fresh[k].items.size(), reused[k].items.size());
        for (size_t t = 0; t < fresh[k].items.size(); ++t) {
          const Annotation &a = fresh[k].items[t], &c = reused[k].items[t];
          EXPECT_TRUE(a.scenario == c.scenario && a.region == c.region && a.x == c.x && a.y == c.y && a.w == c.w &&
                      a.h == c.h && a.area == c.area)
              << "item " << t << " view " << k;
        }
        compared += fresh[k].items.size();
      }
    }
    EXPECT_GT(compared, 1000u);
  }
}

// The kernels' images of white sprites on black: a pixel is lit exactly where the mask
// has an object (integer placement, no noise; coverage >= 1/255 at alpha 0.9 displays >= 1).
TEST(Annotations, MasksAgreeWithTheKernelsPixels) {
  const Catalogue& cat = test::catalogue();
  const AssetSet a = white_on_black();
  std::unique_ptr<Backend> cl = make_opencl_backend(cat, a, test::runtime());
  Plan plan;
  plan.features = false;
  plan.annotations = true;
  plan.model.pattern_noise = false;
  plan.model.jitter = 60;
  plan.model.seed = 3;
  std::vector<Scenario> scenes;
  for (uint64_t k = 0; k < 64; ++k) scenes.push_back(test::random_scenario(cat, k));
  BatchOutput out;
  cl->run(test::batch_of(scenes, 77), plan, out);
  ASSERT_EQ(out.annotations.size(), cat.sensors.size());
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const ViewImages& v = out.views[k];
    const ViewAnnotations& va = out.annotations[k];
    size_t lit = 0;
    for (size_t p = 0; p < v.pixels.size(); ++p) {
      ASSERT_EQ(v.pixels[p] > 0, va.masks[p] > 0) << v.name << " pixel " << p;
      lit += v.pixels[p] > 0;
    }
    EXPECT_GT(lit, 1000u) << v.name;
  }
}

// Randomised objects in the kernels' images of white sprites on black: every lit pixel is
// in the mask (a displayed level >= 1 needs coverage far above fp32's rounding), and the
// mask's pixels are lit but for the faint fringe of bilinear sampling (coverage below
// 0.5 / (255 alpha) displays 0).
TEST(Annotations, MasksOfTransformedObjectsAgreeWithTheKernelsPixels) {
  const Catalogue& cat = test::catalogue();
  const AssetSet a = white_on_black();
  std::unique_ptr<Backend> cl = make_opencl_backend(cat, a, test::runtime());
  for (const bool bilinear : {false, true}) {
    Plan plan;
    plan.features = false;
    plan.annotations = true;
    plan.model.pattern_noise = false;
    plan.model.bilinear = bilinear;
    plan.model.jitter = 60;
    plan.model.seed = 3;
    plan.model.rotate_lo = -90;
    plan.model.rotate_hi = 90;
    plan.model.scale_lo = 0.6;
    plan.model.scale_hi = 1.5;
    plan.model.flip = true;
    std::vector<Scenario> scenes;
    for (uint64_t k = 0; k < 64; ++k) scenes.push_back(test::random_scenario(cat, k));
    BatchOutput out;
    cl->run(test::batch_of(scenes, 77), plan, out);
    for (size_t k = 0; k < cat.sensors.size(); ++k) {
      const ViewImages& v = out.views[k];
      const ViewAnnotations& va = out.annotations[k];
      size_t lit = 0, masked = 0;
      for (size_t p = 0; p < v.pixels.size(); ++p) {
        ASSERT_TRUE(v.pixels[p] == 0 || va.masks[p] > 0) << v.name << " pixel " << p << " bilinear " << bilinear;
        lit += v.pixels[p] > 0;
        masked += va.masks[p] > 0;
      }
      EXPECT_GT(lit, 1000u) << v.name;
      EXPECT_GT(static_cast<double>(lit), 0.9 * static_cast<double>(masked)) << v.name << " bilinear " << bilinear;
    }
  }
}

// Boxes and masks worked out by hand, independent of the placement code (reference::
// view_scene, Sensor::place) that both backends' annotations and the reference composite
// share. The upper view's rectangles for regions 1-3 are set here, and the gun's first
// drawing is an 11x7 sprite whose coverage is the 6x4 block x 3..8, y 2..5. Subject 1
// (height 1: its places do not move); integer placement, no jitter, no transforms. A
// sprite sits at rect.x + floor((rect.w - 11) / 2), rect.y + floor((rect.h - 7) / 2):
//   region 1, rect (40, 30, 20, 10): sprite at (44, 31), coverage x 47..52, y 33..36.
//   region 2, rect (44, 32, 20, 10): sprite at (48, 33), coverage x 51..56, y 35..38; it
//     is drawn over region 1, which keeps 24 - 4 (x 51..52, y 35..36) = 20 pixels.
//   region 3, rect (-4, 100, 8, 10): sprite at (-4 + floor(-3 / 2), 101) = (-6, 101),
//     coverage x -3..2, y 103..106: cut by the view's left edge to x 0..2, 12 pixels.
TEST(Annotations, BoxesAndMasksAgreeWithHandComputedOnes) {
  Catalogue cat = test::catalogue();
  AssetSet a = test::assets();
  const int upper = cat.sensor_index("upper");
  ASSERT_GE(upper, 0);
  Sensor& view = cat.sensors[upper];
  ASSERT_TRUE(view.sees(0) && view.sees(1) && view.sees(2));
  ASSERT_EQ(cat.subjects[0].shape.height, 1.0);
  view.rects[0] = {40, 30, 20, 10};
  view.rects[1] = {44, 32, 20, 10};
  view.rects[2] = {-4, 100, 8, 10};
  const int gun = cat.objects[cat.find_object("gun")].first_variant;
  Image sprite(11, 7, 2, 0);
  for (int y = 2; y <= 5; ++y)
    for (int x = 3; x <= 8; ++x) sprite.at(x, y, 0) = sprite.at(x, y, 1) = 255;
  a.sprites[static_cast<int>(view.camera)][gun] = sprite;

  struct Box {
    int region, x, y, w, h;
    uint32_t area;
  };
  struct Sprite {
    int region, x, y;  // 0-based region holding the gun; where its sprite's corner lands
  };
  struct Case {
    std::vector<Sprite> sprites;
    std::vector<Box> boxes;
  };
  const std::vector<Case> cases{
      {{{0, 44, 31}}, {{0, 47, 33, 6, 4, 24}}},
      {{{0, 44, 31}, {1, 48, 33}}, {{0, 47, 33, 6, 4, 20}, {1, 51, 35, 6, 4, 24}}},
      {{{2, -6, 101}}, {{2, 0, 103, 3, 4, 12}}},
  };
  std::vector<Scenario> scenes;
  for (const Case& c : cases) {
    Scenario s;
    s.subject = 0;
    for (const Sprite& p : c.sprites) s.objects[p.region] = static_cast<int16_t>(gun);
    scenes.push_back(s);
  }
  const SceneBatch b = test::batch_of(scenes, 0);
  ModelSettings m;
  m.jitter = 0;
  std::vector<ViewAnnotations> got;
  annotate(cat, a, m, b, got, 1);
  ASSERT_EQ(got.size(), cat.sensors.size());
  const ViewAnnotations& va = got[upper];
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    // The mask: each box's coverage block painted in region order, clipped to the view.
    std::vector<uint8_t> want(static_cast<size_t>(va.width) * va.height, 0);
    for (const Sprite& p : cases[i].sprites)
      for (int y = p.y + 2; y <= p.y + 5; ++y)
        for (int x = p.x + 3; x <= p.x + 8; ++x)
          if (x >= 0 && y >= 0 && x < va.width && y < va.height)
            want[static_cast<size_t>(y) * va.width + x] = static_cast<uint8_t>(p.region + 1);
    EXPECT_TRUE(std::equal(want.begin(), want.end(), va.mask_of(i)));
    ASSERT_EQ(va.first[i + 1] - va.first[i], cases[i].boxes.size());
    for (size_t t = 0; t < cases[i].boxes.size(); ++t) {
      const Annotation& x = va.items[va.first[i] + t];
      const Box& e = cases[i].boxes[t];
      EXPECT_EQ(x.region, e.region);
      EXPECT_EQ(x.object, cat.find_object("gun"));
      EXPECT_EQ(x.drawing, 0);
      EXPECT_EQ(x.x, e.x) << "region " << e.region + 1;
      EXPECT_EQ(x.y, e.y) << "region " << e.region + 1;
      EXPECT_EQ(x.w, e.w) << "region " << e.region + 1;
      EXPECT_EQ(x.h, e.h) << "region " << e.region + 1;
      EXPECT_EQ(x.area, e.area) << "region " << e.region + 1;
    }
  }
  // The backends report what annotate() computes, and only when asked for.
  std::vector<std::unique_ptr<Backend>> backends;
  backends.push_back(make_reference_backend(cat, a));
  backends.push_back(make_opencl_backend(cat, a, test::runtime()));
  for (const std::unique_ptr<Backend>& backend : backends) {
    Plan plan;
    plan.annotations = true;
    BatchOutput out;
    backend->run(b, plan, out);
    ASSERT_EQ(out.annotations.size(), got.size());
    EXPECT_EQ(out.annotations[upper].masks, va.masks);
    EXPECT_EQ(out.annotations[upper].first, va.first);
    plan.annotations = false;
    backend->run(b, plan, out);
    EXPECT_TRUE(out.annotations.empty()) << "annotations are computed only when asked for";
  }
}

}  // namespace
}  // namespace portalsim
