// The catalogue: everything a scenario can name (thesis chapter 4), read from TOML.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "scene/body_shape.h"
#include "scene/sensor.h"

namespace portalsim {

// Where an image comes from: a file, or (path empty) the procedural default.
struct ImageSource {
  std::string path;    // resolved path, empty for procedural
  std::string origin;  // "file:line: field", for error messages
};

struct Subject {
  std::string name;
  BodyShape shape;  // widths, stature, limbs and pose of its procedural body
  int mmw_level = 150, ir_core = 215, ir_limb = 175;
  // The physics model's skin at 94 GHz and its temperature, where this subject's differ
  // from [physics]'s (0: [physics]'s); PhysicsConfig::skin_emissivity_of reads them.
  double skin_emissivity = 0, skin_temperature = 0;
  // The seed of its procedural body's posture and texture details: -1 for its index.
  int64_t texture = -1;
  // A drawn body's values as scenarios.csv records them (scene/bodies.h, kBodyColumns);
  // empty for the catalogue's subjects.
  std::string drawn;
  std::vector<int> base_zones;  // one per zone of the metal detector
  // The base image files the catalogue names, by camera view name (images.NAME); a view
  // with none draws the procedural body.
  std::map<std::string, ImageSource, std::less<>> images;
  // The base image of the view called `view`: its file, or the procedural source (empty
  // path) where the catalogue names none.
  const ImageSource& image(std::string_view view) const;
};

// A region of the body (thesis 4.1): its rectangle in each view that sees it is the view's
// (Sensor::rects).
struct Region {
  int id = 0;  // 1-based, its place in the catalogue
  std::string name;
};

struct Variant {
  std::string code;                 // "h", "v", or "" for an object with one drawing
  std::vector<ImageSource> images;  // per camera kind (by Camera): its file (key <kind>_<code>), or none
};

// A material of the physics model (docs/model/physics-mmw.md): its emissivity at 94 GHz
// and how fast it warms on the body. The catalogue gives each value's source.
struct Material {
  std::string name;
  double emissivity = 0;    // at 94 GHz; 1 - reflectivity
  double warm_minutes = 1;  // time constant of warming from the room to the skin
};

// The physics model's scene and sensor parameters ([physics] in the catalogue).
struct PhysicsConfig {
  // The MMW camera (thesis appendix A: Millivision Vela 125).
  double frequency_ghz = 94.0, aperture_m = 0.125, fov_rad = 0.43, range_m = 2.0;
  // The scene: skin seen at 94 GHz through clothing, the room behind the subject.
  double skin_emissivity = 0.39, skin_temperature = 306.0;
  double clothing_transmission = 0.9, clothing_temperature = 303.0;
  double background_temperature = 293.0, room_temperature = 293.0;
  // The subject's base image as kelvin: its background gray is background_temperature,
  // the subject's mmw_level is bare body (through clothing); linear in between and beyond.
  int base_background_gray = 25;
  // The IR camera: the base image's temperature index 0 and 255 in kelvin (linear); how much
  // of an object's coolness reaches the clothing surface; the Gaussian heat spreading in the
  // fabric (sigma, mm); the display window in kelvin shown as index 0 and 255.
  double ir_index_min_k = 290.5, ir_index_max_k = 308.9;
  double ir_coupling = 0.8, ir_spread_mm = 10.0;
  double ir_display_min = 290.5, ir_display_max = 308.9;
  // What a surface of emissivity e at physical temperature t shows the MMW camera through
  // the clothing, the scene reflecting `illumination` (docs/model/physics-mmw.md). The
  // kernels' tables and the drawn bodies' gray levels read it; the reference has its own.
  double seen_through_clothing(double e, double t, double illumination) const {
    return clothing_transmission * (e * t + (1 - e) * illumination) +
           (1 - clothing_transmission) * clothing_temperature;
  }
  // A subject's own skin where it gives one, else the values above.
  double skin_emissivity_of(const Subject& s) const {
    return s.skin_emissivity > 0 ? s.skin_emissivity : skin_emissivity;
  }
  double skin_temperature_of(const Subject& s) const {
    return s.skin_temperature > 0 ? s.skin_temperature : skin_temperature;
  }
  // The least IR temperature index that is body: warmer than halfway from the room to the
  // skin (the kernels' contact shadow and the fold patterns read it; the reference has its own).
  int ir_body_index() const {
    return static_cast<int>(std::ceil(((room_temperature + skin_temperature) / 2 - ir_index_min_k) /
                                      ((ir_index_max_k - ir_index_min_k) / 255.0)));
  }
};

struct Object {
  std::string name;
  std::vector<std::string> aliases;
  std::string material;
  int material_id = -1;  // index into Catalogue::materials, -1 where the catalogue has none
  int metal = 0;         // index into Catalogue::metal_categories
  std::string shape;
  int width = 0, height = 0;  // MMW sprite of the horizontal drawing
  std::vector<int> levels;    // per camera kind (by Camera): its drawing's level (key <kind>_level)
  // --model physics: polarizability along the drawing's long axis over across it (1: isotropic).
  double metal_anisotropy = 1.0;
  // What rules and pools can name it by (`class:threat`, `family:knife`); empty where the
  // catalogue gives none (docs/model/objects.md).
  std::string object_class, family;
  std::vector<Variant> variants;
  int first_variant = 0;  // index of variants[0] in Catalogue::variant_list
};

struct NoisePattern {
  std::string name;
  double gain = 1.0;
  ImageSource image;
};

struct ImagesConfig {
  double alpha = 0.9;
  int noise_size = 64;
};

// The walk-through metal detector under --model physics ([metal.physics];
// docs/model/metal.md): per zone, the panel its coil transmits from (A at x < 0, the
// subject's right, or B); it receives on the other panel.
struct MetalPhysics {
  bool present = false;                                // the catalogue has [metal.physics]
  double body_height = 1.75, panel_separation = 0.76;  // m
  double tx_moment = 1.0, rx_moment = 1.0;             // A m^2
  std::vector<int> tx_side;                            // per zone: -1 panel A (x < 0), +1 panel B
  std::vector<double> tx_height, rx_height;            // per zone, m above the floor
  std::vector<double> gain;                            // per zone, counts per unit signal
  std::vector<double> polarizability;                  // cm^3 per metal category
};

// A drawable thing: one variant of one object. Scenes refer to these by index.
struct VariantRef {
  int object = 0;
  int variant = 0;
};

struct Catalogue {
  std::string source;  // the file it came from, or "<built-in catalogue>"
  std::string hash;    // FNV-1a 64 of the text, hex
  ImagesConfig images;
  std::vector<Subject> subjects;
  std::vector<Region> regions;  // [[regions]], at most kMaxRegions
  int zones = 0;                // the metal detector's zones ([metal] zones), at most kMaxZones
  std::vector<Object> objects;
  std::vector<NoisePattern> noise;
  std::vector<Material> materials;
  PhysicsConfig physics;
  std::vector<std::string> metal_categories;
  // influence[category][region][zone]
  std::vector<std::vector<std::vector<int>>> influence;
  std::vector<VariantRef> variant_list;
  // The objects a run draws from when it names no pool (`default_pool`; every object when
  // the catalogue gives none).
  std::vector<int> default_pool;
  std::vector<Sensor> sensors;         // the camera views ([[views]]; scene/sensor.h)
  std::vector<SpriteSet> sprite_sets;  // the objects' drawings the views need
  MetalPhysics metal_physics;

  int region_count() const { return static_cast<int>(regions.size()); }
  const Object& object_of(int variant_id) const { return objects[variant_list[variant_id].object]; }
  const Variant& variant(int variant_id) const {
    const VariantRef& r = variant_list[variant_id];
    return objects[r.object].variants[r.variant];
  }
  // A variant's magnetic polarizability tensor, cm^3, row-major 3x3 in portal axes (x
  // across, y along the walk, z up): m (I + (a - 1) u u^T) 3 / (a + 2), mean m of its metal
  // category, anisotropy a along its long axis u: the drawing's longer side as long_side
  // lays it (x where it is wider than tall, else z; a "v" drawing turned a quarter).
  std::array<double, 9> polarizability(int variant_id) const;
  // The same tensor with its long axis along the unit vector `axis` (portal axes), any
  // orientation: across (I + (a - 1) u u^T), written so that an axis along x or z gives
  // polarizability(variant_id)'s numbers to the bit (metal maps, host/evaluate/metal_map.h).
  std::array<double, 9> polarizability(int variant_id, const std::array<double, 3>& axis) const;
  // A variant's long side as the coils see it, metres (x across, z up): the drawing's
  // longer side (x where it is wider than tall, else z; a "v" drawing turned a quarter) at
  // the metal model's scale (metres_per_field_unit).
  std::array<double, 2> long_side(int variant_id) const;
  // The metal model's scale: the field's height is [metal.physics] body_height.
  double metres_per_field_unit() const { return metal_physics.body_height / kFieldHeight; }
  // Every object's name, comma-separated in catalogue order: what messages list as known.
  std::string object_names() const;
  // "gun:v" for display; "gun" where the object has one drawing.
  std::string variant_name(int variant_id) const;
  // Finds an object by name or alias, ignoring case and punctuation ("Iron Rod",
  // "iron_rod", "IRON-ROD" are all iron-rod). Returns -1 when unknown.
  int find_object(std::string_view name) const;
  // Index of the camera view called `name` in `sensors`, or -1.
  int sensor_index(std::string_view name) const;
};

// Reads a catalogue. `source_name` is used in messages; `base_dir` resolves relative
// image paths (assets_dir, when given, takes precedence). Throws InputError naming
// file, line and field for anything malformed.
Catalogue parse_catalogue(std::string_view text, const std::string& source_name, const std::string& base_dir,
                          const std::string& assets_dir = "");
Catalogue load_catalogue(const std::string& path, const std::string& assets_dir = "");
Catalogue default_catalogue(const std::string& assets_dir = "");

std::string normalise_name(std::string_view name);

}  // namespace portalsim
