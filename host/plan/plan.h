// What a batch needs: which sensors, images or features only, and the model's knobs.
// Both backends read the same Plan; what it leaves out is never computed.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "assets/procedural.h"
#include "scene/catalogue.h"
#include "scene/clothing.h"
#include "scene/scene.h"

namespace portalsim {

// How the MMW camera interpolates its raw grid to the view: bilinear, or Keys' cubic
// convolution (a = -1/2), edges held.
enum class DisplayFilter { bilinear, bicubic };

// A knob drawn per scenario: uniform in [lo, hi], whole numbers for an integer knob.
struct DrawnRange {
  double lo = 0, hi = 0;
  bool varies() const { return hi > lo; }
};

// The knobs of the sensor model (docs/model/thesis.md). Each field's default is its
// knob's declaration (plan/knobs.cpp; the thesis's values): ModelSettings() holds them all.
struct ModelSettings {
  ModelSettings();
  // Every field zero, what the knobs' defaults are set on (plan/knobs.cpp).
  struct Bare {};
  explicit ModelSettings(Bare) {}

  uint64_t seed = 0;  // the run's, not a knob
  Model model{};
  bool pattern_noise{};  // thesis 4.2: one of the MMW noise patterns over each object
  double pixel_sigma{};  // per-pixel Gaussian sensor noise, gray levels (MMW and IR)
  int metal_noise{};     // detector noise: triangular integer noise, half-width in counts
  int block{};           // side of the averaged pixel blocks (thesis 5.6)
  // Sprite placement: each object moves by jitter * (2u - 1) pixels in x and y (u from
  // the counter generator), rounded to whole pixels, or kept sub-pixel with bilinear
  // sampling. The noise tiles stay where the unmoved sprite would be.
  bool bilinear{};
  double jitter{};
  // Randomised objects (docs/model/randomised-objects.md): each object turns by an angle
  // uniform in [rotate_lo, rotate_hi] degrees about its sprite's centre (counter-clockwise
  // as seen in the image), scales by a factor uniform in [scale_lo, scale_hi], and with
  // `flip` is mirrored left to right with probability 1/2; drawn per (scenario, region)
  // from the counter generator (object_transform), the same in every view. Any of them
  // on makes the composite sample sprites through the inverse affine map, bilinearly.
  double rotate_lo{}, rotate_hi{};
  double scale_lo{}, scale_hi{};
  bool flip{};
  // The physics model (docs/model/physics-mmw.md); ignored by the thesis model.
  double illumination{};          // K: what the body and objects reflect (the room, indoors)
  double netd{};                  // K rms: MMW sensor noise per raw pixel
  int raw_width{}, raw_height{};  // the MMW camera's raw grid over each view
  // The raw grids a run draws from (--mmw-raw 24x24,28x28; docs/model/drawn-knobs.md), each
  // {width, height}, raw_width x raw_height the first; empty where the grid is fixed. Each
  // scenario's is raw_grid_at's; a backend runs each grid's scenarios together.
  std::vector<std::array<int, 2>> raw_grids;
  double worn_minutes{};  // how long the objects have been carried (their temperature)
  double ir_netd{};       // K rms: IR sensor noise per pixel
  // The clothing (docs/model/clothing.md): the catalogue's, or outfits drawn per scenario
  // (outfit_at); at_scenario resolves the scenario's outfit, an index into
  // outfit_table(clothing) (-1: the catalogue's clothing).
  Clothing clothing{};
  int outfit = -1;
  // The outer garment's folds and seams (--clothing-folds): the share of the view's fold
  // pattern (AssetSet::folds) where it lies doubled, 0 (none) .. 1; each scenario's is
  // drawn_knob_at's. Only under a drawn outfit.
  double clothing_folds{};
  // The MMW camera's own processing (docs/model/physics-mmw.md, "The camera's defaults"):
  // raw frames at 10 Hz averaged, each with its own NETD draw (the default 10: one second,
  // the body 5+ times the noise in both views); the display window, fixed [window_lo,
  // window_hi] kelvin (the default 290..302: room 293 K and body 298.6 K well inside it,
  // 3 sigma of noise unclipped) or set per image from the raw grid's 1st and 99th
  // percentiles (window_auto), or each end drawn per scenario (window_drawn: drawn's
  // PS_DRAWN_WINDOW_LO and _HI, window_lo and window_hi holding their ranges' low ends); the
  // interpolation from the raw grid to the view, and a Gaussian of `smooth` view pixels.
  int frames{};
  bool window_auto{};
  double window_lo{}, window_hi{};
  DisplayFilter display_filter{};
  double smooth{};
  // Knobs drawn per scenario (docs/model/drawn-knobs.md), indexed by PS_DRAWN_*: a knob
  // given A..B takes in each scenario a value uniform in [A, B] (whole numbers for an
  // integer knob) from the counter generator, the same in every view, batch and backend.
  // Its field above then holds A; its value in a scenario is drawn_knob_at's. Its knob's
  // declaration (plan/knobs.cpp, drawable) names its element and field.
  std::array<DrawnRange, PS_DRAWN_KNOBS> drawn{};
  // The knobs as view `s` takes them: its own camera parameters (Sensor::netd, raw) over
  // the run's. Both backends read a view's knobs through this, and nothing else.
  ModelSettings for_view(const Sensor& s) const;
  // The knobs of scenario `index`: each drawn knob at its value there (drawn_knob_at,
  // outfit_at, raw_grid_at), nothing drawn. The CPU reference computes each scenario from these.
  ModelSettings at_scenario(uint64_t index) const;
  // The pixel noise's highest sigma: the knob's, or its drawn range's upper end.
  double pixel_sigma_hi() const {
    return drawn[PS_DRAWN_PIXEL_NOISE].varies() ? drawn[PS_DRAWN_PIXEL_NOISE].hi : pixel_sigma;
  }
  bool raw_grid_drawn() const { return raw_grids.size() > 1; }
  bool has_folds() const { return clothing_folds > 0 || drawn[PS_DRAWN_CLOTHING_FOLDS].varies(); }
  bool window_drawn() const { return drawn[PS_DRAWN_WINDOW_LO].varies() || drawn[PS_DRAWN_WINDOW_HI].varies(); }
  bool transforms() const { return rotate_lo != 0 || rotate_hi != 0 || scale_lo != 1 || scale_hi != 1 || flip; }
  bool moves_sprites() const { return bilinear || jitter > 0 || transforms(); }
};

// The draw of the randomised-object knobs for scenario `index`'s object in region r
// (0-based), identity when they are off: PS_STREAM_TRANSFORM, element r, words
// 0 and 1 uniform (24 bits) for the angle and the scale, the top bit of word 2 for the flip.
// kernels/composite.cl's place_view draws the same numbers on its own.
ObjectTransform object_transform(const ModelSettings& m, uint64_t index, int region);

// Scenario `index`'s value of the drawn number `element` (PS_DRAWN_*; knobs.h, DrawnKnob): its
// knob's value, or where it is drawn (A..B) A + (B - A) uniform24(word 0) of PS_STREAM_KNOB_DRAW,
// element `element`, for a real knob, A + below(word 0, B - A + 1) for a whole one (metal_noise,
// frames). The kernels draw the same on their own (kernels/lib/philox.cl, knob_draw).
double drawn_knob_at(const ModelSettings& m, unsigned element, uint64_t index);
// Scenario `index`'s outfit, an index into outfit_table(m.clothing), -1 for the catalogue's
// clothing: its class below(word 0, classes), then its outfit in the class below(word 1,
// the class's outfits), of PS_STREAM_KNOB_DRAW element PS_DRAWN_CLOTHING. kernels/lib/physics.cl's
// scene_draw draws the same.
int outfit_at(const ModelSettings& m, uint64_t index);
// That outfit itself, for a run whose clothing is drawn (m.clothing not the catalogue's).
const Outfit& outfit_of(const ModelSettings& m, uint64_t index);
// The most raw grids a list may hold (--mmw-raw WxH,WxH,...): each is a part of every batch.
constexpr size_t kMaxRawGrids = 16;
// Scenario `index`'s MMW raw grid, {width, height}: the run's, or where a list is drawn
// (ModelSettings::raw_grids) its entry below(word 0, size) of PS_STREAM_KNOB_DRAW element
// PS_DRAWN_MMW_RAW. The OpenCL backend runs each grid's scenarios as a batch of their own.
std::array<int, 2> raw_grid_at(const ModelSettings& m, uint64_t index);

// How block and region means are computed. Both give the same numbers to the bit
// (under -cl-fast-relaxed-math, to the division's approximation); sparse is used for
// features-only runs without per-pixel noise, dense otherwise.
enum class Pooling { sparse, dense };
// The arithmetic of the kernels' pixel values.
enum class Precision { fp32, fp64, fixed16 };
// Per-pixel sensor noise, or (features-only runs) its effect on each mean drawn
// directly: N(0, sigma^2 / pixels), ignoring rounding and clipping.
enum class NoiseModel { per_pixel, block_mean };
// How the sensor noise is drawn (docs/model/determinism.md): the normal draws, Box-Muller
// (thesis pixels, two to a Philox draw) or the quantile table (physics NETD); or for both
// models Irwin-Hall, eight values to a draw, the two bytes of a 16-bit half summed and
// shaped by a quintic (not quite normal: |g| <= 3.37).
enum class NoiseDraw { box_muller, irwin_hall };

// The speed/accuracy knobs of the OpenCL backend (docs/model/tiers.md). None of
// them changes what is modelled; each changes how closely the kernels follow the fp64
// reference, and how fast.
struct Fidelity {
  Precision precision = Precision::fp32;
  Pooling pooling = Pooling::sparse;
  bool fast_math = false;  // -cl-fast-relaxed-math
  NoiseModel noise = NoiseModel::per_pixel;
  NoiseDraw draw = NoiseDraw::box_muller;
  // Camera views rendered by the fast view paths where their gates apply (backend/opencl/
  // paths/), or all by the chain of stage kernels, one launch per stage; the same bits.
  bool fused = true;
};

enum class Tier { fast, standard, exact };
Fidelity tier_fidelity(Tier t);
Tier parse_tier(const std::string& name, const std::string& where);
const char* tier_name(Tier t);
const char* precision_name(Precision p);

// The palette knob's default (plan/knobs.cpp).
procedural::PaletteName default_palette();

// Bit k of Plan::images: camera view k (Catalogue::sensors) is materialised.
constexpr uint32_t kAllViews = ~0u;

struct Plan {
  uint32_t images = kAllViews;  // which camera views' images the caller keeps
  bool metal = true;            // metal zones
  bool features = true;         // block and region means of the pooled views
  bool annotations = false;     // per-object boxes and instance masks (backend/annotate.h)
  // Every scenario has a subject of its own (--bodies per-scenario): paths whose per-subject
  // tables cost more than rendering a page's scenarios step aside.
  bool own_subjects = false;
  ModelSettings model;
  Fidelity fidelity;
  // How the IR temperature index is written as RGB (images, h5 `ir`, serve); not part of
  // either model: the stored index is the same. Its default is its knob's.
  procedural::PaletteName palette = default_palette();

  bool image(int view) const { return (images >> view) & 1u; }
  // A view is rendered when its images are kept or it is pooled into features; views
  // nobody asked for are never rendered.
  bool renders(const Sensor& s, int view) const { return image(view) || (features && s.pooled); }
  // Per-pixel noise drawn pixel by pixel (otherwise none, or the block-mean model).
  bool pixel_noise_per_pixel() const {
    return model.pixel_sigma_hi() > 0 && (images != 0 || fidelity.noise == NoiseModel::per_pixel);
  }
  // The MMW camera's frames as the kernels draw them: one each, or (block-mean noise model,
  // the fast tier) one draw of NETD / sqrt(frames).
  bool frames_approximated() const {
    return fidelity.noise == NoiseModel::block_mean && (model.frames > 1 || model.drawn[PS_DRAWN_FRAMES].varies());
  }
  // The physics cameras' noise draws (MMW NETD, IR NETD) under noise_draw irwin-hall (the
  // fast tier's), the knob the thesis model's pixel noise follows: Irwin-Hall draws without
  // the table (kernels/contract.h, PS_IH_*); the reference draws them alike.
  bool physics_draws_approximated() const { return fidelity.draw == NoiseDraw::irwin_hall; }
};

// The layout of a feature row: the blocks of each pooled view in turn (row-major,
// partial blocks at the right and bottom edges averaged over the pixels they hold), the
// catalogue's region means (13 in the built-in one), then its metal zones (19); sinks
// append the class. Each pooled view has its own grid of blocks.
struct FeatureLayout {
  struct Grid {
    int blocks_x = 0, blocks_y = 0;
    int offset = 0;  // its first column
    int blocks() const { return blocks_x * blocks_y; }
  };
  int block = 10;
  int regions = 0, zones = 0;  // the catalogue's
  std::vector<int> pooled;     // the pooled views (indices into Catalogue::sensors)
  std::vector<std::string> view_names;
  std::vector<Grid> grids;  // per pooled view
  // Every pooled view has one size (so one grid): what the features paths' tables assume
  // (backend/opencl/paths/); the other layouts take the pooled views rendered.
  bool uniform = true;
  int block_features() const { return grids.empty() ? 0 : grids.back().offset + grids.back().blocks(); }
  int image_features() const { return block_features() + regions; }
  int row_features() const { return image_features() + zones; }
  std::vector<std::string> names() const;
  static FeatureLayout of(const Catalogue& cat, int block);
  // The smallest square block side that cuts every pooled view into w x h blocks (5x5 on
  // the 200x200 MMW views is block 40, the thesis's grid), or 0 when none does.
  static int block_for_grid(const Catalogue& cat, int w, int h);
};

// Checks the plan's numbers; throws InputError naming the option.
void validate(const Plan& plan, const Catalogue& cat);

}  // namespace portalsim
