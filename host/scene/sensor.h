// A camera view as a descriptor: what it is called, its size, the regions it sees and
// where they are, which sprites and base images it draws, and which stages apply.
// Code iterates over Catalogue::sensors; a new camera view is a new entry here plus its
// assets, not a new field in every struct.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "contract.h"

namespace portalsim {

constexpr int kRegions = PS_REGIONS;
constexpr int kZones = PS_ZONES;

struct Rect {
  int x = 0, y = 0, w = 0, h = 0;
};

// Which sprites and palette a view uses: the camera it belongs to.
enum class Camera : int { mmw = 0, ir = 1 };
// Which sensor model renders a scenario: the thesis's composite, or the physically based
// one (docs/model/physics-mmw.md). Each camera view has a stage chain per model.
enum class Model { thesis = 0, physics = 1 };
const char* model_name(Model m);
constexpr int kCameras = 2;
inline const char* camera_name(Camera c) { return c == Camera::ir ? "ir" : "mmw"; }

struct Sensor {
  std::string name;       // "upper", "lower", "ir": file stems, column prefixes, data set names
  std::string asset_key;  // the subject's catalogue key for its base image: "mmw_upper", "ir"
  Camera camera = Camera::mmw;
  int width = 0, height = 0;
  // Region r's rectangle in this view, for the regions it sees (bit r of region_mask).
  std::array<Rect, kRegions> rects{};
  uint32_t region_mask = 0;
  bool pattern_noise = false;  // the thesis's MMW noise patterns are laid over objects
  bool pooled = false;         // its block and region means are features
  bool palette = false;        // stored as a temperature index, written through the palette
  // Jitter is given in MMW pixels; this view's pixels per MMW pixel.
  double jitter_scale_x = 1.0, jitter_scale_y = 1.0;
  // The floor's row in this view's pixel coordinates (the bottom edge of the lower MMW
  // view; for the upper view one view height below its own bottom).
  double floor_row = 0.0;
  // Per subject, how many whole pixels down each region's place moves with the subject's
  // stature (Subject::height, scaled about the floor): round((1 - height) (floor_row - c)),
  // c the region's centre row. Zero for height 1.
  std::vector<std::array<int, kRegions>> subject_dy;
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
    r.y += subject_dy[subject][region];
    return r;
  }
  size_t pixels() const { return static_cast<size_t>(width) * height; }
};

struct Catalogue;
// The camera views of a catalogue, in output order: MMW upper, MMW lower, IR.
std::vector<Sensor> camera_sensors(const Catalogue& cat);

}  // namespace portalsim
