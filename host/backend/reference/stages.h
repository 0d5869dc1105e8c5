// The reference's stages: the sensor model written as plainly as possible, in double
// precision, one pixel at a time. Each is a free function under the stage's name, the
// same name as its kernel in kernels/ and its entry in backend/stages.h. They share with
// kernels/ only the contract header's constants and layouts (kernels/contract.h, through
// scene/), never a computation (tests/layering_check.py); the random draws follow
// docs/model/determinism.md (draws.h).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "assets/assets.h"
#include "backend/reference/stage_list.h"
#include "plan/plan.h"
#include "scene/scene.h"

namespace portalsim::reference {

// A camera view's values before display: gray levels (MMW) or temperature indices (IR).
struct Field {
  int width = 0, height = 0;
  std::vector<double> v;
  double& at(int x, int y) { return v[static_cast<size_t>(y) * width + x]; }
  double at(int x, int y) const { return v[static_cast<size_t>(y) * width + x]; }
};

// One object drawn in a view: its sprite, where it sits centred in its region (the noise
// tile's place), and its placement jitter in this view's pixels.
struct Placed {
  const Image* sprite;
  int x0, y0;
  double dx, dy;
  int variant;                // the object drawing
  ObjectTransform transform;  // randomised objects (identity when off)
};

// Randomised objects: where pixel (x, y) samples a placed sprite, turned, scaled and
// mirrored about its centre, and the box of pixels it can touch (inclusive, unclipped).
struct SpriteMap {
  double cx, cy;              // the sprite's centre in the image
  double csx, csy;            // and in the sprite: ((w - 1) / 2, (h - 1) / 2)
  double a00, a01, a10, a11;  // the inverse map: sprite - sprite centre = A (image - centre)
  int x0, y0, x1, y1;
  // The sprite point (sx, sy) of pixel (x, y).
  void at(int x, int y, double& sx, double& sy) const;
};
// The map of `p` at integer (jitter rounded) or bilinear placement.
SpriteMap sprite_map(const Placed& p, bool bilinear);

// Everything a stage of one camera view reads for one scenario.
struct ViewScene {
  const Catalogue& cat;
  const AssetSet& assets;
  const ModelSettings& model;  // the view's knobs of this scenario: drawn knobs at their draws
  const Sensor& sensor;
  int view;  // index in Catalogue::sensors
  const Scenario& scenario;
  uint64_t index;  // the scenario's global index: the random generator's counter
  std::vector<Placed> placed;
  // How the plan draws the noise: the pixel draw (Fidelity::draw), which the physics
  // cameras' NETD follows too (fast_gaussian's under irwin-hall: Plan::physics_draws_approximated),
  // and the MMW frames as one draw of NETD / sqrt(frames) (Plan::frames_approximated).
  NoiseDraw draw = NoiseDraw::box_muller;
  bool frames_as_one = false;
  void follow(const Plan& plan) {
    draw = plan.fidelity.draw;
    frames_as_one = plan.frames_approximated();
  }
};

ViewScene view_scene(const Catalogue& cat, const AssetSet& assets, const ModelSettings& model, int view,
                     const Scenario& s, uint64_t index);

// Lays each placed object over `f` in region order, at its whole-pixel or sub-pixel place:
// v = a s + (1 - a) v, a = alpha * coverage, s = value(object, sprite x, sprite y).
void lay_objects(const ViewScene& vs, Field& f, double alpha,
                 double (*value)(const ViewScene&, const Placed&, int, int));

// The stages (stage_list.h), each transforming the field in place: the thesis chain
// (composite, pattern_noise, sensor_noise, display), the physics MMW chain (radiometry,
// optics, sample, netd, window, mmw_display) and the IR chain (contact_shadow, heat_spread,
// ir_surface, ir_netd, ir_display).
#define PORTALSIM_DECLARE_STAGE(name, ...) void name(const ViewScene& vs, Field& f);
PORTALSIM_STAGES(PORTALSIM_DECLARE_STAGE)
#undef PORTALSIM_DECLARE_STAGE

// The physics model's quantities, from the catalogue and the knobs.
// The scenario's outfit (m.outfit >= 0), innermost layer first: what each layer passes at
// 94 GHz and its temperature, K.
struct LayerSeen {
  double transmission, temperature;
};
std::vector<LayerSeen> outfit_layers(const PhysicsConfig& pc, const ModelSettings& m);
// The share of the skin's excess over the room that reaches the outfit's surface (IR).
// With outer_doubled, where the outer garment lies twice (its folds and seams).
double outfit_surface_share(const ModelSettings& m, bool outer_doubled = false);
double body_temperature(const Catalogue& cat, const ModelSettings& m, const Subject& s);  // bare body under clothing, K
double worn_temperature(const Catalogue& cat, const ModelSettings& m, int variant,
                        double skin);  // physical, K, warmed on skin of this temperature
double object_temperature(const Catalogue& cat, const ModelSettings& m, int variant);  // apparent, under clothing
double contact_shadow_kelvin(const Catalogue& cat, const ModelSettings& m, int variant,
                             const Subject& subject);               // IR surface dT on this subject, full cover
double ir_spread_pixels(const Catalogue& cat, const Sensor& view);  // heat spreading's sigma in IR view pixels
void gaussian_blur(Field& f, double sigma);                         // separable, edges held; sigma in pixels
double psf_fwhm_pixels(const Catalogue& cat, const Sensor& view);   // the Airy core's FWHM in view pixels

// Block means of each pooled view, then each region's mean (thesis 5.6); `views` holds the
// displayed images of every camera view (empty where not rendered).
void pool(const Catalogue& cat, const std::vector<std::vector<uint8_t>>& views, const FeatureLayout& layout,
          float* row);
// Metal zones (thesis algorithm step 2): base minus every object's influence, clamped. `m`
// is the scenario's knobs (ModelSettings::at_scenario), as every stage's.
void metal(const Catalogue& cat, const ModelSettings& m, const Scenario& s, uint64_t index, uint8_t* zones);

// Metal zones under --model physics (metal_physics.cpp): base minus round(gain |sum of
// H_R^T M H_T|), at most 199, detector noise as the thesis model's, clamped to [1, 200].
void metal_physics(const Catalogue& cat, const AssetSet& assets, const ModelSettings& m, const Scenario& s,
                   uint64_t index, uint8_t* zones);
// A metal object as the coils see it: polarizability tensor (cm^3) and position (metres,
// x across the portal, y along the walk, z up), its region's centre in the stacked MMW
// views, moved with the subject's height as the composite's place (Sensor::place), plus the
// composite's placement jitter; a scenario's objects stand at y = 0, a metal map's walk
// through (host/evaluate/metal_map.h).
// It is PS_METAL_SEGMENTS dipoles of tensor / PS_METAL_SEGMENTS each, at the midpoints of
// equal segments of its long side (lx, ly, lz) about (x, y, z). y and ly come last so that
// {tensor, x, z, lx, lz} still reads as before.
struct MetalObject {
  std::array<double, 9> tensor;
  double x, z;
  double lx = 0, lz = 0;
  double y = 0, ly = 0;
};
std::vector<MetalObject> metal_objects(const Catalogue& cat, const AssetSet& assets, const ModelSettings& m,
                                       const Scenario& s, uint64_t index);
// One object's H_R^T M H_T in zone `zone` (0-based), summed over its dipoles, before the gain.
double zone_signal(const MetalPhysics& mp, int zone, const MetalObject& o);
// One object alone, every zone: its response gain |H_R^T M H_T| (counts, unrounded) and
// its deduction, the response rounded half up and capped at 199 (metal maps).
void metal_response(const MetalPhysics& mp, const MetalObject& o, double* response, uint8_t* deduction);

}  // namespace portalsim::reference
