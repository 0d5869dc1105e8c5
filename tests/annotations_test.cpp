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
// makes > 0; the highest region covering a pixel owns it.
Expected expected_mask(const AssetSet& a, const ModelSettings& m, int view, const Scenario& s, uint64_t index) {
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
    // The sprite's whole coverage at this placement, as if the view had no edges.
    const Image& sp = *alone.placed[0].sprite;
    int whole = 0;
    for (size_t i = 1; i < sp.pixels.size(); i += 2) whole += sp.pixels[i] > 0;
    if (covered == 0) ++e.outside;
    if (covered > 0 && !m.bilinear && covered < whole) ++e.cut_off;
  }
  return e;
}

TEST(Annotations, MasksAndBoxesAgreeWithTheReferenceComposite) {
  const Catalogue& cat = test::catalogue();
  const AssetSet a = white_on_black();
  int occluded = 0, cut_off = 0, outside = 0, checked = 0;
  for (const bool bilinear : {false, true})
    for (const double jitter : {0.0, 30.0, 140.0}) {
      ModelSettings m;
      m.seed = 5;
      m.bilinear = bilinear;
      m.jitter = jitter;
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
              << jitter;
          cut_off += e.cut_off;
          outside += e.outside;
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
            const Expected solo = expected_mask(a, m, static_cast<int>(k), alone, 1000 + i);
            const auto solo_area = static_cast<uint32_t>(std::count(solo.mask.begin(), solo.mask.end(), x.region + 1));
            EXPECT_LE(area, solo_area);
            occluded += area < solo_area;
          }
          int regions_visible = 0;
          for (int r = 1; r <= kRegions; ++r) regions_visible += seen[r];
          EXPECT_EQ(listed, regions_visible);
          ++checked;
        }
    }
  // The cases the test is for must have happened.
  EXPECT_GT(occluded, 5) << "no object was covered by another";
  EXPECT_GT(cut_off, 5) << "no object was cut off by the view's edge";
  EXPECT_GT(outside, 5) << "no object fell outside its view";
  EXPECT_EQ(checked, 2 * 3 * 40 * static_cast<int>(cat.sensors.size()));
}

// annotate() clears a reused buffer only where it painted before: batches of other sizes
// and scenes through one buffer must give what fresh buffers give.
TEST(Annotations, ReusedBuffersGiveWhatFreshOnesGive) {
  const Catalogue& cat = test::catalogue();
  ModelSettings m;
  m.jitter = 20;
  std::vector<ViewAnnotations> reused;
  size_t compared = 0;
  for (const auto& [first, n] : std::vector<std::pair<uint64_t, size_t>>{{0, 50}, {300, 20}, {900, 70}, {40, 70}}) {
    std::vector<Scenario> scenes;
    for (uint64_t k = 0; k < n; ++k) scenes.push_back(test::random_scenario(cat, first + k));
    const SceneBatch b = test::batch_of(scenes, first);
    std::vector<ViewAnnotations> fresh;
    annotate(cat, test::assets(), m, b, fresh, 2);
    annotate(cat, test::assets(), m, b, reused, 2);
    for (size_t k = 0; k < fresh.size(); ++k) {
      ASSERT_EQ(fresh[k].masks, reused[k].masks) << "batch at " << first << " view " << k;
      EXPECT_EQ(fresh[k].first, reused[k].first);
      compared += fresh[k].items.size();
    }
  }
  EXPECT_GT(compared, 300u);
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
                    x.h == y.h && x.area == y.area && x.dx == y.dx && x.dy == y.dy);
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
