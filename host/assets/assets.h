// The images a catalogue names, resolved: procedural defaults or the user's files.
#pragma once
#include <array>
#include <vector>

#include "assets/image.h"
#include "scene/catalogue.h"

namespace portalsim {

using Palette = std::array<std::array<uint8_t, 3>, 256>;

struct AssetSet {
  // Per subject: [0] MMW upper, [1] MMW lower (gray), [2] IR (temperature index); 1 channel,
  // at the catalogue's view sizes.
  std::vector<std::array<Image, 3>> bases;
  // Per variant id: 2 channels (value, alpha). IR sprites are temperature indices.
  std::vector<Image> mmw_sprites, ir_sprites;
  // Per noise pattern: 1 channel, 128 = no change, noise_size square.
  std::vector<Image> noise;
  Palette palette{};
};

// Throws InputError naming the catalogue field and file for a missing or corrupt image.
AssetSet build_assets(const Catalogue& cat);

// Converts a loaded user image: to gray (luminance), to a temperature index (nearest
// palette colour for RGB captures), with alpha taken from the last channel when present.
Image to_gray(const Image& img, bool keep_alpha);
Image to_temperature(const Image& img, const Palette& palette, bool keep_alpha);
Image colourise(const Image& temperature, const Palette& palette);

}  // namespace portalsim
