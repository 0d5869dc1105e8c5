#include "backend/opencl/device_catalogue.h"

#include <stdexcept>

#include "backend/opencl/buffers.h"

namespace portalsim::opencl {

namespace {
cl_int4 rect4(const Rect& r) { return {{r.x, r.y, r.w, r.h}}; }
}  // namespace

Rect sprite_box(const Rect& rc, const Image& sprite) {
  return {rc.x + ((rc.w - sprite.width) >> 1), rc.y + ((rc.h - sprite.height) >> 1), sprite.width, sprite.height};
}

int region_slot(const Catalogue& cat, const FeatureLayout& lay, int r) {
  for (size_t slot = 0; slot < lay.pooled.size(); ++slot)
    if (cat.sensors[lay.pooled[slot]].sees(r)) return static_cast<int>(slot);
  return 0;
}

DeviceCatalogue::DeviceCatalogue(const Catalogue& cat, const AssetSet& assets, cl::Context& ctx) {
  std::vector<uint8_t> atlas_bytes;
  auto add = [&](const Image& img) {
    const int off = static_cast<int>(atlas_bytes.size());
    atlas_bytes.insert(atlas_bytes.end(), img.pixels.begin(), img.pixels.end());
    return off;
  };
  const size_t V = cat.variant_list.size(), views = cat.sensors.size();
  const int R = cat.region_count();
  std::vector<cl_int> base_offsets;
  // Room for the images, so that a run of 255 random bodies copies its atlas once: the bases
  // and fold patterns, each sprite three times (plain, and as value and coverage rows with
  // padding), each noise tile twice.
  size_t bytes = 0;
  for (const auto* set : {&assets.bases, &assets.folds})
    for (const auto& subject_views : *set)
      for (const Image& img : subject_views) bytes += img.pixels.size();
  for (const std::vector<Image>& set : assets.sprites)
    for (const Image& sp : set) bytes += 2 * sp.pixels.size() + 2 * size_t(sp.height) * (sp.width + 2 * PS_PAD);
  for (const Image& tile : assets.noise) bytes += tile.pixels.size() + size_t(tile.height) * (tile.width + 2 * PS_PAD);
  atlas_bytes.reserve(bytes);
  // Each subject's base images, then their fold patterns (kernels/lib/view.cl, fold_row).
  for (const auto& subject_views : assets.bases)
    for (const Image& img : subject_views) base_offsets.push_back(add(img));
  for (const auto& subject_views : assets.folds)
    for (const Image& img : subject_views) base_offsets.push_back(add(img));
  // The vector render path's copies (kernels/shared.h, PS_PAD): each sprite row as a
  // value row and a coverage row, each tile row, with neutral pixels on both sides.
  auto add_padded_sprite = [&](const Image& img) {
    const int off = static_cast<int>(atlas_bytes.size());
    for (int y = 0; y < img.height; ++y)
      for (int c = 0; c < 2; ++c) {
        atlas_bytes.insert(atlas_bytes.end(), PS_PAD, 0);
        for (int x = 0; x < img.width; ++x) atlas_bytes.push_back(img.at(x, y, c));
        atlas_bytes.insert(atlas_bytes.end(), PS_PAD, 0);
      }
    return off;
  };
  auto add_padded_tile = [&](const Image& img) {
    const int off = static_cast<int>(atlas_bytes.size());
    for (int y = 0; y < img.height; ++y) {
      atlas_bytes.insert(atlas_bytes.end(), PS_PAD, 128);
      for (int x = 0; x < img.width; ++x) atlas_bytes.push_back(img.at(x, y));
      atlas_bytes.insert(atlas_bytes.end(), PS_PAD, 128);
    }
    return off;
  };
  variants = V;
  for (const std::vector<Image>& set : assets.sprites)
    for (const Image& sp : set) {
      const int plain = add(sp);
      sprite_records.push_back({{plain, sp.width, sp.height, add_padded_sprite(sp)}});
    }
  // Each sprite centred in its region's rectangle of each view; then, per subject and
  // view, how far each region's place moves with the subject's height (Sensor::place),
  // which place_view adds.
  const size_t S = cat.subjects.size();
  std::vector<cl_int2> place_records((views * V + S * views) * R);
  for (size_t k = 0; k < views; ++k) {
    const Sensor& s = cat.sensors[k];
    for (size_t v = 0; v < V; ++v) {
      const Image& sp = assets.sprite(s, static_cast<int>(v));
      for (int r = 0; r < R; ++r) {
        const Rect box = sprite_box(s.rects[r], sp);
        place_records[(k * V + v) * R + r] = {{box.x, box.y}};
      }
    }
    for (size_t j = 0; j < S; ++j)
      for (int r = 0; r < R; ++r)
        place_records[(views * V + j * views + k) * R + r] = {{s.subject_dx[j][r], s.subject_dy[j][r]}};
  }
  std::vector<cl_int> tile_offsets;
  std::vector<cl_float> tile_gains;
  for (size_t k = 0; k < assets.noise.size(); ++k) {
    tile_offsets.push_back(add(assets.noise[k]));
    tile_gains.push_back(static_cast<float>(cat.noise[k].gain));
  }
  for (const Image& tile : assets.noise) tile_offsets.push_back(add_padded_tile(tile));
  if (atlas_bytes.size() > 0x7fffffffu) throw std::runtime_error("catalogue images exceed 2 GiB");

  // Pooled views: each region's rectangle in the pooled view that sees it.
  const FeatureLayout lay = FeatureLayout::of(cat, 1);
  std::vector<cl_int> pooled_views(lay.pooled.begin(), lay.pooled.end()), slots(R, 0);
  std::vector<cl_int4> rects(R);
  for (int r = 0; r < R; ++r)
    for (size_t slot = 0; slot < lay.pooled.size(); ++slot) {
      const Sensor& s = cat.sensors[lay.pooled[slot]];
      if (!s.sees(r)) continue;
      slots[r] = static_cast<cl_int>(slot);
      rects[r] = rect4(s.rects[r]);
      break;
    }
  std::vector<cl_int4> all_view_rects;
  for (const Sensor& s : cat.sensors)
    for (int r = 0; r < R; ++r) all_view_rects.push_back(rect4(s.rects[r]));

  std::vector<uint8_t> influence_bytes, category_bytes, base_zone_bytes;
  for (const auto& table : cat.influence)
    for (const auto& row : table)
      for (int z : row) influence_bytes.push_back(static_cast<uint8_t>(z));
  for (size_t v = 0; v < V; ++v)
    category_bytes.push_back(static_cast<uint8_t>(cat.object_of(static_cast<int>(v)).metal));
  for (const Subject& s : cat.subjects)
    for (int z : s.base_zones) base_zone_bytes.push_back(static_cast<uint8_t>(z));

  atlas = constant(ctx, atlas_bytes);
  bases = constant(ctx, base_offsets);
  sprites = constant(ctx, sprite_records);
  places = constant(ctx, place_records);
  noise_offsets = constant(ctx, tile_offsets);
  noise_gains = constant(ctx, tile_gains);
  pooled = constant(ctx, pooled_views);
  region_slot = constant(ctx, slots);
  region_rects = constant(ctx, rects);
  for (size_t k = 0; k < views; ++k)
    view_rects.push_back(
        constant(ctx, std::vector<cl_int4>(all_view_rects.begin() + k * R, all_view_rects.begin() + (k + 1) * R)));
  influence = constant(ctx, influence_bytes);
  categories = constant(ctx, category_bytes);
  base_zones = constant(ctx, base_zone_bytes);
}

}  // namespace portalsim::opencl
