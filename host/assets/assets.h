// The images a catalogue names, resolved: procedural defaults or the user's files.
#pragma once
#include <array>
#include <vector>

#include "assets/image.h"
#include "scene/catalogue.h"

namespace portalsim {

using Palette = std::array<std::array<uint8_t, 3>, 256>;

struct AssetSet {
  // Per subject, per camera view (Catalogue::sensors order): 1 channel at the view's size,
  // gray (MMW) or temperature index (IR).
  std::vector<std::vector<Image>> bases;
  // Per subject, per view, as bases: the outer garment's fold and seam pattern over the
  // body (procedural::fold_pattern), 0 .. 255 the share where it lies doubled.
  std::vector<std::vector<Image>> folds;
  // Per sprite set (Catalogue::sprite_sets), per variant id: 2 channels (value, alpha);
  // gray for MMW, temperature indices for IR, at the set's scale, mirrored for back views.
  std::vector<std::vector<Image>> sprites;
  // Per noise pattern: 1 channel, 128 = no change, noise_size square.
  std::vector<Image> noise;
  Palette palette{};

  const Image& sprite(const Sensor& view, int variant) const { return sprites[view.sprite_set][variant]; }
};

// Throws InputError naming the catalogue field and file for a missing or corrupt image.
// Without fold_patterns, `folds` stays empty (a run that gives no --clothing-folds: a run of
// 255 random bodies draws them in 0.2 s and carries 30 MB more to the device).
AssetSet build_assets(const Catalogue& cat, bool fold_patterns = true);
// `base` (built for a catalogue like `cat` but for its subjects) with `cat`'s subjects'
// bases, and their folds where `base` has folds: a page of per-scenario bodies
// (scene/bodies.h, use_page_bodies) keeps the run's sprites and noise.
AssetSet with_subjects(const AssetSet& base, const Catalogue& cat);

// Converts a loaded user image: to gray (luminance), to a temperature index (nearest
// palette colour for RGB captures), with alpha taken from the last channel when present.
Image to_gray(const Image& img, bool keep_alpha);
Image to_temperature(const Image& img, const Palette& palette, bool keep_alpha);
Image colourise(const Image& temperature, const Palette& palette);
// The same for `n` one-channel indices into `rgb` (3n bytes).
void colourise(const uint8_t* index, size_t n, const Palette& palette, uint8_t* rgb);

}  // namespace portalsim
