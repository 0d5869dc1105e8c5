// Stage "annotations": per object and camera view, the pixels it visibly owns, as an
// instance mask and a tight box. Integer geometry from the scene and the sprites'
// coverage, computed on the host by this one function for both backends, so the two
// give the same bytes.
//
// Visible: object k covers pixel p when its sprite's coverage (alpha) at p, sampled as
// the composite stage samples it, is > 0: at integer placement the texel under p; at
// bilinear placement (and for randomised objects, at the sprite point of the inverse
// affine map) any texel with a non-zero bilinear weight. Objects are composited in
// region order, so p belongs to the covering object of the highest region. The mask
// holds that region's number (1..13), 0 for none. An object with no visible pixel (out of
// the view, or covered whole) has no annotation.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "assets/assets.h"
#include "plan/plan.h"
#include "scene/scene.h"

namespace portalsim {

struct Annotation {
  uint32_t scenario = 0;           // position in the batch
  uint8_t region = 0;              // 0-based; the mask holds region + 1
  int16_t object = 0;              // index into Catalogue::objects (the category)
  int16_t drawing = 0;             // index into the object's variants (h, v)
  int x = 0, y = 0, w = 0, h = 0;  // tight box of the visible pixels
  uint32_t area = 0;               // visible pixels
  double dx = 0, dy = 0;           // the sprite's placement offset: whole pixels, or sub-pixel (bilinear)
  double rotation = 0, scale = 1;  // randomised objects: degrees counter-clockwise, and the factor
  bool flip = false;               // mirrored left to right
};

struct ViewAnnotations {
  int width = 0, height = 0;
  std::vector<uint8_t> masks;     // n * height * width
  std::vector<Annotation> items;  // by scenario, then region
  std::vector<uint32_t> first;    // n + 1: scenario i's items are [first[i], first[i + 1])
  const uint8_t* mask_of(size_t i) const { return masks.data() + i * static_cast<size_t>(width) * height; }

  // Where annotate() painted each mask, so that a reused buffer is cleared there only
  // rather than whole; a size that differs from the masks' count means "clear all".
  struct Painted {
    int count = 0;
    std::array<std::array<int16_t, 4>, kMaxRegions> box{};  // x0, y0, x1, y1 inclusive
  };
  std::vector<Painted> painted;
};

// Annotates batches of one catalogue and asset set, keeping between batches what does
// not change: each sprite's covered texels, where sprites that do not move sit, and the
// workers' scratch masks and lists (the backends hold one). `cat` and `assets` must
// outlive it; one batch at a time.
class Annotator {
 public:
  Annotator(const Catalogue& cat, const AssetSet& assets);
  ~Annotator();
  Annotator(const Annotator&) = delete;
  Annotator& operator=(const Annotator&) = delete;
  // One ViewAnnotations per camera view (Catalogue::sensors order) for the batch.
  void operator()(const ModelSettings& model, const SceneBatch& batch, std::vector<ViewAnnotations>& out,
                  unsigned threads = 1);

 private:
  struct Kept;
  std::unique_ptr<Kept> kept_;
};

// The same with an Annotator of its own: for one batch.
void annotate(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model, const SceneBatch& batch,
              std::vector<ViewAnnotations>& out, unsigned threads = 1);

}  // namespace portalsim
