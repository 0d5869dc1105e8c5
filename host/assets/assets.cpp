#include "assets/assets.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "assets/image_io.h"
#include "assets/procedural.h"
#include "base/error.h"
#include "base/parallel.h"

namespace portalsim {

namespace {

bool has_alpha(const Image& img) { return img.channels == 2 || img.channels == 4; }

int luminance(const Image& img, int x, int y) {
  if (img.channels < 3) return img.at(x, y, 0);
  return (299 * img.at(x, y, 0) + 587 * img.at(x, y, 1) + 114 * img.at(x, y, 2) + 500) / 1000;
}

Image load(const ImageSource& src) { return read_image(src.path, src.origin); }

Image sized(Image img, int w, int h) { return resize_image(img, w, h); }

// A file as a view of `kind` stores it: temperature indices (nearest palette colour), or gray.
Image as_stored(const CameraKind& kind, const Image& img, const Palette& palette, bool keep_alpha) {
  return kind.palette ? to_temperature(img, palette, keep_alpha) : to_gray(img, keep_alpha);
}

Image mirrored(const Image& img) {
  Image out(img.width, img.height, img.channels);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < img.channels; ++c) out.at(img.width - 1 - x, y, c) = img.at(x, y, c);
  return out;
}

}  // namespace

Image to_gray(const Image& img, bool keep_alpha) {
  Image out(img.width, img.height, keep_alpha ? 2 : 1);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      out.at(x, y, 0) = static_cast<uint8_t>(luminance(img, x, y));
      if (keep_alpha) out.at(x, y, 1) = has_alpha(img) ? img.at(x, y, img.channels - 1) : 255;
    }
  return out;
}

Image to_temperature(const Image& img, const Palette& palette, bool keep_alpha) {
  if (img.channels < 3) return to_gray(img, keep_alpha);
  Image out(img.width, img.height, keep_alpha ? 2 : 1);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      int best = 0, best_d = 1 << 30;
      for (int t = 0; t < 256; ++t) {
        int d = 0;
        for (int c = 0; c < 3; ++c) {
          const int e = img.at(x, y, c) - palette[t][c];
          d += e * e;
        }
        if (d < best_d) best_d = d, best = t;
      }
      out.at(x, y, 0) = static_cast<uint8_t>(best);
      if (keep_alpha) out.at(x, y, 1) = has_alpha(img) ? img.at(x, y, img.channels - 1) : 255;
    }
  return out;
}

Image colourise(const Image& temperature, const Palette& palette) {
  Image out(temperature.width, temperature.height, 3);
  const size_t n = static_cast<size_t>(temperature.width) * temperature.height;
  if (temperature.channels == 1) {
    colourise(temperature.pixels.data(), n, palette, out.pixels.data());
    return out;
  }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) out.pixels[i * 3 + c] = palette[temperature.pixels[i * temperature.channels]][c];
  return out;
}

void colourise(const uint8_t* index, size_t n, const Palette& palette, uint8_t* rgb) {
  for (size_t i = 0; i < n; ++i) std::memcpy(rgb + 3 * i, palette[index[i]].data(), 3);
}

namespace {

// Each subject's base images and, with fold_patterns, their folds.
void draw_subjects(AssetSet& a, const Catalogue& cat, bool fold_patterns) {
  // Each subject's base images; drawn ones on every core (a run of random bodies draws up
  // to 255), files one at a time.
  a.bases.resize(cat.subjects.size());
  const auto draw = [&](size_t s) {
    const Subject& sub = cat.subjects[s];
    procedural::Body body;
    body.subject = sub.texture >= 0 ? static_cast<int>(sub.texture) : static_cast<int>(s);
    body.shape = sub.shape;
    body.mmw_level = sub.mmw_level;
    body.ir_core = sub.ir_core;
    body.ir_limb = sub.ir_limb;
    std::vector<Image>& views = a.bases[s];
    for (const Sensor& view : cat.sensors) {
      const CameraKind& kind = camera_kind(view.camera);
      const ImageSource& src = sub.image(view.name);
      if (!src.path.empty())
        views.push_back(sized(as_stored(kind, load(src), a.palette, false), view.width, view.height));
      else
        views.push_back(kind.palette ? procedural::ir_view(body, view.field, view.side, view.width, view.height)
                                     : procedural::mmw_view(body, view.field, view.side, view.width, view.height));
    }
  };
  const bool files =
      std::any_of(cat.subjects.begin(), cat.subjects.end(), [](const Subject& s) { return !s.images.empty(); });
  parallel_for(cat.subjects.size(), files ? 1 : default_threads(), [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) draw(s);
  });
  // Each base's folds over its body: gray pixels nearer the subject's body gray than the
  // room's, temperature indices warmer than halfway from the room to the skin (as the IR
  // contact shadow's test).
  if (fold_patterns) {
    const PhysicsConfig& pc = cat.physics;
    a.folds.resize(cat.subjects.size());
    parallel_for(cat.subjects.size(), default_threads(), [&](size_t begin, size_t end) {
      for (size_t s = begin; s < end; ++s) {
        const Subject& sub = cat.subjects[s];
        const int texture = sub.texture >= 0 ? static_cast<int>(sub.texture) : static_cast<int>(s);
        const int bg = pc.base_background_gray, level = sub.mmw_level, mid = (bg + level + 1) / 2;
        for (size_t v = 0; v < cat.sensors.size(); ++v) {
          const Sensor& view = cat.sensors[v];
          const bool index = view.palette;
          const int lo = index ? pc.ir_body_index() : (level >= bg ? mid : 0);
          const int hi = index ? 255 : (level >= bg ? 255 : mid);
          a.folds[s].push_back(procedural::fold_pattern(a.bases[s][v], view, lo, hi, texture));
        }
      }
    });
  }
}

}  // namespace

AssetSet with_subjects(const AssetSet& base, const Catalogue& cat) {
  AssetSet a;
  a.palette = base.palette;
  a.sprites = base.sprites;
  a.noise = base.noise;
  draw_subjects(a, cat, !base.folds.empty());
  return a;
}

AssetSet build_assets(const Catalogue& cat, bool fold_patterns) {
  AssetSet a;
  a.palette = procedural::ir_palette();
  const ImagesConfig& ic = cat.images;
  draw_subjects(a, cat, fold_patterns);
  // Each sprite set's drawings keep the objects' physical size: a catalogue size is in field
  // units, scaled by the set's view pixels per unit. A file is its camera's drawing as given.
  // Drawn on every thread (each drawing stands alone), files one at a time as the bases are.
  const size_t V = cat.variant_list.size();
  for (size_t set = 0; set < cat.sprite_sets.size(); ++set) a.sprites.emplace_back(V);
  const auto draw_sprite = [&](size_t job) {
    const SpriteSet& set = cat.sprite_sets[job / V];
    const size_t v = job % V;
    const CameraKind& kind = camera_kind(set.camera);
    const Object& o = cat.object_of(static_cast<int>(v));
    const Variant& var = cat.variant(static_cast<int>(v));
    const bool vertical = var.code == "v";
    const int w = vertical ? o.height : o.width, h = vertical ? o.width : o.height;
    const int sw = std::max(1, static_cast<int>(std::lround(w * set.scale_x)));
    const int sh = std::max(1, static_cast<int>(std::lround(h * set.scale_y)));
    const auto k = static_cast<size_t>(set.camera);
    const ImageSource& file = var.images[k];
    Image sp = !file.path.empty() ? as_stored(kind, load(file), a.palette, true)
                                  : procedural::sprite(o.shape, vertical, sw, sh, o.levels[k]);
    a.sprites[job / V][v] = set.mirrored ? mirrored(sp) : std::move(sp);
  };
  const bool sprite_files = std::any_of(cat.objects.begin(), cat.objects.end(), [](const Object& o) {
    return std::any_of(o.variants.begin(), o.variants.end(), [](const Variant& v) {
      return std::any_of(v.images.begin(), v.images.end(), [](const ImageSource& s) { return !s.path.empty(); });
    });
  });
  parallel_for(cat.sprite_sets.size() * V, sprite_files ? 1 : default_threads(), [&](size_t begin, size_t end) {
    for (size_t job = begin; job < end; ++job) draw_sprite(job);
  });
  for (size_t k = 0; k < cat.noise.size(); ++k) {
    const NoisePattern& p = cat.noise[k];
    a.noise.push_back(p.image.path.empty() ? procedural::noise_pattern(static_cast<int>(k), ic.noise_size)
                                           : sized(to_gray(load(p.image), false), ic.noise_size, ic.noise_size));
  }
  return a;
}

}  // namespace portalsim
