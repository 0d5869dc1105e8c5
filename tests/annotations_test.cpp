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
  for (int r = 0; r < kRegions; ++r) {
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
    reference::Field big;
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
        for (uint64_t k = 0; k < 40; ++k) scenes.push_back(test::random_scenario(cat, k));
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
            std::vector<int> seen(kRegions + 1, 0);
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
            for (int r = 1; r <= kRegions; ++r) regions_visible += seen[r];
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
  EXPECT_EQ(checked, 2 * 2 * 3 * 40 * static_cast<int>(cat.sensors.size()));
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

// Both backends give the same annotations to the byte: one host function computes them.
TEST(Annotations, BackendsGiveIdenticalAnnotations) {
  const Catalogue& cat = test::catalogue();
  std::unique_ptr<Backend> ref = make_reference_backend(cat, test::assets());
  std::unique_ptr<Backend> cl = make_opencl_backend(cat, test::assets(), test::runtime());
  for (const bool bilinear : {false, true}) {
    Plan plan;
    plan.annotations = true;
    plan.model.bilinear = bilinear;
    plan.model.jitter = 12.5;
    plan.model.seed = 11;
    plan.model.rotate_lo = bilinear ? -30 : 0;  // integer placement: scale and flip only
    plan.model.rotate_hi = bilinear ? 60 : 0;
    plan.model.scale_lo = 0.8;
    plan.model.scale_hi = 1.25;
    plan.model.flip = true;
    std::vector<Scenario> scenes;
    for (uint64_t k = 0; k < 24; ++k) scenes.push_back(test::random_scenario(cat, k));
    const SceneBatch b = test::batch_of(scenes, 500);
    BatchOutput r, c;
    ref->run(b, plan, r);
    cl->run(b, plan, c);
    ASSERT_EQ(r.annotations.size(), c.annotations.size());
    size_t items = 0;
    for (size_t k = 0; k < r.annotations.size(); ++k) {
      EXPECT_EQ(r.annotations[k].masks, c.annotations[k].masks);
      EXPECT_EQ(r.annotations[k].first, c.annotations[k].first);
      ASSERT_EQ(r.annotations[k].items.size(), c.annotations[k].items.size());
      for (size_t t = 0; t < r.annotations[k].items.size(); ++t) {
        const Annotation &x = r.annotations[k].items[t], &y = c.annotations[k].items[t];
        EXPECT_TRUE(x.region == y.region && x.object == y.object && x.x == y.x && x.y == y.y && x.w == y.w &&
                    x.h == y.h && x.area == y.area && x.dx == y.dx && x.dy == y.dy && x.rotation == y.rotation &&
                    x.scale == y.scale && x.flip == y.flip);
      }
      items += r.annotations[k].items.size();
    }
    EXPECT_GT(items, 50u);
    plan.annotations = false;
    ref->run(b, plan, r);
    EXPECT_TRUE(r.annotations.empty()) << "annotations are computed only when asked for";
  }
}

}  // namespace
}  // namespace portalsim
