// The default images, drawn by portalsim itself so that nothing is downloaded.
// Every function is a pure function of its arguments: integer and double arithmetic
// with an integer hash for texture, no platform RNG, so the bytes are the same on
// every machine and every run.
#pragma once
#include <array>
#include <string>

#include "assets/image.h"
#include "scene/body_shape.h"
#include "scene/builtin_images.h"
#include "scene/sensor.h"

namespace portalsim::procedural {

// Body geometry is given for the MMW views (200x200 each, subject facing the camera,
// so the subject's right side is on the image's left). The IR view covers the whole
// body at half scale: IR(x, y) = MMW upper(2x, 2y) for y < h/2, MMW lower(2x, 2(y - h/2))
// below. Functions scale these proportions to the width and height asked for.
struct Body {
  int subject = 0;  // 0-based; varies posture and texture a little
  // Widths, stature, limb lengths and pose (scene/body_shape.h). Stature scales about the
  // floor (the bottom edge of the lower view); the views stay where they are, so a taller
  // body's shoulders leave the upper view's top and its hips move up into the upper view.
  BodyShape shape;
  int mmw_level = 150;  // gray of the body in MMW (passive emission of skin)
  int mmw_background = 25;
  int ir_core = 215;  // IR temperature index of the torso (warmest)
  int ir_limb = 175;  // IR temperature index of the limbs and head edges
  int ir_background = 35;
};

// 1 channel gray: the part `field` of the portal's field (scene/sensor.h, Frame) as the MMW
// camera sees it from `side` (the back mirrored, with a texture of its own).
Image mmw_view(const Body& body, const Frame& field, Side side, int width, int height);
// 1 channel temperature index (0 cold .. 255 hot), the same for the IR camera.
Image ir_view(const Body& body, const Frame& field, Side side, int width, int height);
// The thesis's views: the upper (shoulders to hips) or lower (hips to feet) MMW view, and
// the whole body in IR, from the front.
Image mmw_body(const Body& body, bool upper, int width, int height);
Image ir_body(const Body& body, int width, int height);

// The outer garment's folds and seams over a view's body (docs/model/clothing.md): per pixel,
// the share (0 .. 255) where the garment lies doubled. A body pixel is one whose base value
// lies in [body_lo, body_hi]. Creases run across the body every 22 field units, wavy, each of
// its own depth (from `texture`), in field coordinates so that every view of a body shows
// the same ones; seams run 3 units inside each edge of every run of body pixels along a row
// (sleeves, trouser legs, the trunk's sides) and down the middle of runs over 40 units wide.
Image fold_pattern(const Image& base, const Sensor& view, int body_lo, int body_hi, int texture);

// The object outlines of the thesis (section 4.3.1). width/height are the sprite's
// final size (already swapped for a vertical variant); `vertical` turns the drawing.
// Returns 2 channels: value (gray for MMW, temperature index for IR) and alpha
// (coverage, 255 inside, 0 outside, anti-aliased edge). `level` is the mean value of
// the object's material; the drawing adds shading and detail around it.
// Throws std::invalid_argument for a name not in kProceduralShapes.
Image sprite(const std::string& shape, bool vertical, int width, int height, int level);

// The k-th (0 .. kProceduralNoisePatterns-1) MMW noise pattern: 1 channel, 128 means no change, value-128 is added
// to the image. Its amplitude falls to 0 at the tile's border, so it stays local.
Image noise_pattern(int k, int size);

// 256-entry RGB palettes for IR temperature indices: ironbow, like the thesis's figure 4.13
// (black, blue, magenta, red, orange, yellow, white; also how RGB captures are read), gray
// (white hot), rainbow (blue cold to red and white hot).
enum class PaletteName { ironbow = 0, gray = 1, rainbow = 2 };
const char* palette_name(PaletteName p);
std::array<std::array<uint8_t, 3>, 256> ir_palette(PaletteName which = PaletteName::ironbow);

}  // namespace portalsim::procedural
