// A camera view as a descriptor: what it is called, its size, the regions it sees and
// where they are, which sprites and base images it draws, and which stages apply.
// Code iterates over Catalogue::sensors; a new camera view is a new entry here plus its
// assets, not a new field in every struct.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "contract.h"
#include "scene/camera_kind.h"

namespace portalsim {

// The most regions and detector zones a catalogue may declare (kernels/contract.h); the
// catalogue's own counts are Catalogue::regions.size() and Catalogue::zones.
constexpr int kMaxRegions = PS_MAX_REGIONS;
constexpr int kMaxZones = PS_MAX_ZONES;

struct Rect {
  int x = 0, y = 0, w = 0, h = 0;
};

// Which side of the body a view sees: a back view sees the body from behind, mirrored.
enum class Side : int { front = 0, back = 1 };
inline const char* side_name(Side s) { return s == Side::back ? "back" : "front"; }

// The portal's field: the frame the procedural body is drawn in, in the thesis's MMW pixels
// (200 across, the two 200 x 200 MMW views stacked, the floor at its bottom edge). Views,
// their sprites' scale and the metal detector's object positions are all given in it.
constexpr double kFieldWidth = 200.0, kFieldHeight = 400.0;
struct Frame {
  double x = 0, y = 0, w = kFieldWidth, h = kFieldHeight;
};
// Which sensor model renders a scenario: the thesis's composite, or the physically based
// one (docs/model/physics-mmw.md). Each camera view has a stage chain per model.
enum class Model { thesis = 0, physics = 1 };
const char* model_name(Model m);

// The objects' drawings one or more views share: one camera's sprites at one scale (view
// pixels per field unit), mirrored for back views.
struct SpriteSet {
  Camera camera = Camera::mmw;
  double scale_x = 1.0, scale_y = 1.0;
  bool mirrored = false;
  bool operator==(const SpriteSet&) const = default;
};

struct Sensor {
  std::string name;  // "upper", "lower", "ir": file stems, column prefixes, data set names,
                     // and the key of the subjects' base images ([[subjects]] images.NAME)
  Camera camera = Camera::mmw;
  Side side = Side::front;
  int width = 0, height = 0;
  Frame field;         // the part of the portal's field it shows
  int sprite_set = 0;  // its objects' drawings: index into Catalogue::sprite_sets
  // Region r's rectangle in this view, for the regions it sees (bit r of region_mask).
  std::array<Rect, kMaxRegions> rects{};
  uint32_t region_mask = 0;
  bool pattern_noise = false;  // the thesis's MMW noise patterns are laid over objects
  bool pooled = false;         // its block and region means are features
  // The physics model's camera, where this view's differs from the run's knobs
  // (ModelSettings::for_view): its NETD, K rms (an MMW view's per raw pixel, over --netd;
  // an IR view's per pixel, over --ir-netd), and an MMW view's raw grid (over --mmw-raw).
  std::optional<double> netd;
  std::optional<std::array<int, 2>> raw;
  bool palette = false;  // stored as a temperature index, written through the palette
  // Jitter is given in MMW pixels (field units); this view's pixels per field unit.
  double jitter_scale_x = 1.0, jitter_scale_y = 1.0;
  // The floor's row in this view's pixel coordinates (the bottom edge of the lower MMW
  // view; for the upper view one view height below its own bottom).
  double floor_row = 0.0;
  // Per subject, how many whole pixels down each region's place moves with the subject's
  // stature (Subject::height, scaled about the floor): round((1 - height) (floor_row - c)),
  // c the region's centre row. Zero for height 1.
  std::vector<std::array<int, kMaxRegions>> subject_dy;
  // Per subject, how many whole pixels across it moves with the body's width at that row
  // (scene/body_shape.h, drawn_col), where the subject's breadths are given; else zero.
  std::vector<std::array<int, kMaxRegions>> subject_dx;
  // The stages of its chain under each model, in order (names registered in
  // backend/stages.cpp).
  std::vector<std::string> chain{"composite", "pattern_noise", "sensor_noise", "display"};
  std::vector<std::string> physics_chain = chain;
  const std::vector<std::string>& chain_for(Model m) const { return m == Model::physics ? physics_chain : chain; }

  bool sees(int region) const { return (region_mask >> region) & 1u; }
  // Where region `region` holds an object on subject `subject`: its rectangle, moved with
  // the subject's body. Object placement (both backends, annotations, metal positions)
  // goes through this; pooling uses `rects` as they are.
  Rect place(int subject, int region) const {
    Rect r = rects[region];
    r.x += subject_dx[subject][region];
    r.y += subject_dy[subject][region];
    return r;
  }
  size_t pixels() const { return static_cast<size_t>(width) * height; }
  // A point of this view (pixel coordinates) in the portal's field: a back view mirrored.
  double field_col(double col) const {
    return side == Side::back ? field.x + field.w - col / jitter_scale_x : field.x + col / jitter_scale_x;
  }
  double field_row(double row) const { return field.y + row / jitter_scale_y; }
  // Field units per pixel of this view, across (negative for a back view) and down.
  double field_per_col() const { return (side == Side::back ? -1.0 : 1.0) / jitter_scale_x; }
  double field_per_row() const { return 1.0 / jitter_scale_y; }
};

// The first view that sees region r, -1 where none does. The metal detector places a
// region's object where its first view draws it.
int first_view(const std::vector<Sensor>& views, int region);
// The same among the views of kinds whose views are the features' (CameraKind::feature_views).
int first_feature_view(const std::vector<Sensor>& views, int region);

struct Catalogue;
// What a catalogue's [[views]] entry leaves to be derived: the chains and flags of its
// camera, its scales and floor row, its sprite set (added to cat.sprite_sets when new) and
// each subject's place offsets. The views' names, cameras, sides, sizes, fields, region
// rectangles and pooling are read from the catalogue first.
void derive_view(Catalogue& cat, Sensor& s);
// The part of it that follows the subjects: each subject's place offsets (subject_dx, subject_dy).
void derive_places(const Catalogue& cat, Sensor& s);

}  // namespace portalsim
