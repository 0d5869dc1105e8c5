#include "scene/catalogue.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <stdexcept>

#include "base/embedded.h"
#include "base/error.h"
#include "io/input_file.h"
#include "io/toml_input.h"
#include "scene/builtin_images.h"

namespace portalsim {

namespace {

struct Reader {
  std::string file;
  std::string base_dir;
  std::string assets_dir;

  [[noreturn]] void fail(const toml::node* node, const std::string& field, const std::string& msg) const {
    std::ostringstream s;
    s << file;
    if (node && node->source().begin.line > 0) s << ":" << node->source().begin.line;
    s << ": " << field << ": " << msg;
    throw InputError(s.str());
  }

  const toml::node* need(const toml::table& t, const std::string& key, const std::string& field) const {
    const toml::node* n = t.get(key);
    if (!n) fail(&t, field, "missing");
    return n;
  }

  long long integer(const toml::node* n, const std::string& field, long long lo, long long hi) const {
    if (!n->is_integer()) fail(n, field, "expected an integer");
    const long long v = n->as_integer()->get();
    if (v < lo || v > hi)
      fail(n, field,
           "value " + std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  int integer(const toml::table& t, const std::string& key, const std::string& field, long long lo, long long hi,
              std::optional<int> dflt = std::nullopt) const {
    const toml::node* n = t.get(key);
    if (!n) {
      if (dflt) return *dflt;
      fail(&t, field + "." + key, "missing");
    }
    return static_cast<int>(integer(n, field + "." + key, lo, hi));
  }

  double number(const toml::table& t, const std::string& key, const std::string& field, double lo, double hi,
                std::optional<double> dflt = std::nullopt) const {
    const toml::node* n = t.get(key);
    const std::string f = field + "." + key;
    if (!n) {
      if (dflt) return *dflt;
      fail(&t, f, "missing");
    }
    return number(n, f, lo, hi);
  }
  double number(const toml::node* n, const std::string& f, double lo, double hi) const {
    double v;
    if (n->is_integer())
      v = static_cast<double>(n->as_integer()->get());
    else if (n->is_floating_point())
      v = n->as_floating_point()->get();
    else
      fail(n, f, "expected a number");
    if (!std::isfinite(v)) fail(n, f, "must be a finite number, not NaN or infinity");
    if (v < lo || v > hi) {
      std::ostringstream s;
      s << "value " << v << " is out of range [" << lo << ", " << hi << "]";
      fail(n, f, s.str());
    }
    return v;
  }

  std::string string(const toml::table& t, const std::string& key, const std::string& field,
                     std::optional<std::string> dflt = std::nullopt) const {
    const toml::node* n = t.get(key);
    if (!n) {
      if (dflt) return *dflt;
      fail(&t, field + "." + key, "missing");
    }
    if (!n->is_string()) fail(n, field + "." + key, "expected a string");
    return n->as_string()->get();
  }

  std::vector<int> ints(const toml::node* n, const std::string& field, size_t count, long long lo, long long hi) const {
    const toml::array* a = n->as_array();
    if (!a) fail(n, field, "expected an array of " + std::to_string(count) + " integers");
    if (a->size() != count)
      fail(n, field, "expected " + std::to_string(count) + " values, found " + std::to_string(a->size()));
    std::vector<int> out;
    for (size_t i = 0; i < a->size(); ++i)
      out.push_back(static_cast<int>(integer(a->get(i), field + "[" + std::to_string(i) + "]", lo, hi)));
    return out;
  }

  std::vector<double> numbers(const toml::table& t, const std::string& key, const std::string& field, int count,
                              double lo, double hi) const {
    const std::string f = field + "." + key;
    const toml::node* n = need(t, key, f);
    const toml::array* a = n->as_array();
    if (!a || a->size() != static_cast<size_t>(count))
      fail(n, f, "expected an array of " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (int i = 0; i < count; ++i) out.push_back(number(a->get(i), f + "[" + std::to_string(i) + "]", lo, hi));
    return out;
  }

  Rect rect(const toml::node* n, const std::string& f, int view_w, int view_h) const {
    const std::vector<int> v = ints(n, f, 4, -100000, 100000);
    const Rect r{v[0], v[1], v[2], v[3]};
    if (r.w < 1 || r.h < 1) fail(n, f, "width and height must be at least 1");
    if (r.x < 0 || r.y < 0 || r.x + r.w > view_w || r.y + r.h > view_h)
      fail(n, f, "rectangle lies outside the " + std::to_string(view_w) + "x" + std::to_string(view_h) + " view");
    return r;
  }

  ImageSource image(const toml::table& t, const std::string& key, const std::string& field) const {
    ImageSource src;
    const toml::node* n = t.get(key);
    if (!n) return src;
    if (!n->is_string()) fail(n, field + "." + key, "expected a file name");
    std::string p = n->as_string()->get();
    if (p.empty()) fail(n, field + "." + key, "empty file name");
    namespace fs = std::filesystem;
    fs::path path(p);
    if (path.is_relative()) {
      if (!assets_dir.empty() && fs::exists(fs::path(assets_dir) / path))
        path = fs::path(assets_dir) / path;
      else if (!base_dir.empty())
        path = fs::path(base_dir) / path;
    }
    src.path = path.string();
    src.origin = file + ":" + std::to_string(n->source().begin.line) + ": " + field + "." + key;
    return src;
  }

  const toml::array& array_of_tables(const toml::table& root, const std::string& key) const {
    const toml::node* n = need(root, key, key);
    const toml::array* a = n->as_array();
    if (!a || !a->is_array_of_tables()) fail(n, key, "expected [[" + key + "]] tables");
    return *a;
  }
};

// A numeric key of a catalogue table, declared once: its range, its default (the field's
// value, where the key may be left out) and the field it sets, a number or an integer. The
// sections read their keys from these lists in order, and refuse any other key, so a
// bound, a message and the list of known keys all come from one line.
template <class T>
struct NumberKey {
  const char* key;
  double lo, hi;
  double T::*number = nullptr;
  int T::*integer = nullptr;
  const char* above = nullptr;  // a key before it in the list whose value it must exceed
};

// [physics]: every key optional (the physics model's defaults, PhysicsConfig).
constexpr NumberKey<PhysicsConfig> kPhysicsKeys[] = {
    {"frequency_ghz", 1.0, 10000.0, &PhysicsConfig::frequency_ghz},
    {"aperture_m", 1e-3, 100.0, &PhysicsConfig::aperture_m},
    {"fov_rad", 1e-3, 3.0, &PhysicsConfig::fov_rad},
    {"range_m", 0.01, 1000.0, &PhysicsConfig::range_m},
    {"skin_emissivity", 0.0, 1.0, &PhysicsConfig::skin_emissivity},
    {"skin_temperature", 1.0, 1000.0, &PhysicsConfig::skin_temperature},
    {"clothing_transmission", 0.0, 1.0, &PhysicsConfig::clothing_transmission},
    {"clothing_temperature", 1.0, 1000.0, &PhysicsConfig::clothing_temperature},
    {"background_temperature", 1.0, 1000.0, &PhysicsConfig::background_temperature},
    {"room_temperature", 1.0, 1000.0, &PhysicsConfig::room_temperature},
    {"base_background_gray", 0, 254, nullptr, &PhysicsConfig::base_background_gray},
    {"ir_index_min_k", 1.0, 1000.0, &PhysicsConfig::ir_index_min_k},
    {"ir_index_max_k", 1.0, 1000.0, &PhysicsConfig::ir_index_max_k, nullptr, "ir_index_min_k"},
    {"ir_coupling", 0.0, 1.0, &PhysicsConfig::ir_coupling},
    {"ir_spread_mm", 0.0, 1000.0, &PhysicsConfig::ir_spread_mm},
    {"ir_display_min", 0.0, 1000.0, &PhysicsConfig::ir_display_min},
    {"ir_display_max", 0.0, 1000.0, &PhysicsConfig::ir_display_max, nullptr, "ir_display_min"},
};

// [images]: optional but for alpha.
constexpr NumberKey<ImagesConfig> kImagesKeys[] = {
    {"alpha", 0.0, 1.0, &ImagesConfig::alpha},
    {"noise_size", 1, 4096, nullptr, &ImagesConfig::noise_size},
};
constexpr const char* kImagesRequired[] = {"alpha"};

// [metal.physics]'s single values, all required; the ranges keep every value physical and
// every computed signal finite. Its per-zone arrays follow (kMetalZoneKeys).
constexpr NumberKey<MetalPhysics> kMetalPhysicsKeys[] = {
    {"body_height", 0.5, 3.0, &MetalPhysics::body_height},
    {"panel_separation", 0.2, 5.0, &MetalPhysics::panel_separation},
    {"tx_moment", 1e-6, 1e6, &MetalPhysics::tx_moment},
    {"rx_moment", 1e-6, 1e6, &MetalPhysics::rx_moment},
};
struct ZoneArrayKey {
  const char* key;
  double lo, hi;
  std::vector<double> MetalPhysics::*values;
};
constexpr ZoneArrayKey kMetalZoneKeys[] = {
    {"tx_height", 0.0, 5.0, &MetalPhysics::tx_height},
    {"rx_height", 0.0, 5.0, &MetalPhysics::rx_height},
    {"gain", 0.0, 1e12, &MetalPhysics::gain},
};

// [[materials]]'s numbers, both required.
constexpr NumberKey<Material> kMaterialKeys[] = {
    {"emissivity", 0.0, 1.0, &Material::emissivity},
    {"warm_minutes", 1e-3, 1e6, &Material::warm_minutes},
};

// [[subjects]]: the body's shape over the 1.0 body (scene/body_shape.h's ranges); a breadth
// left out is the build, the rest 1.0.
struct ShapeKey {
  const char* key;
  BodyRange range;
  double BodyShape::*field;
  bool defaults_to_build;
};
constexpr ShapeKey kShapeKeys[] = {
    {"build", kBuildRange, &BodyShape::build, false},
    // Stature about the 1.75 m body of [metal.physics] (docs/model/subjects.md).
    {"height", kHeightRange, &BodyShape::height, false},
    {"shoulders", kBreadthRange, &BodyShape::shoulders, true},
    {"chest", kBreadthRange, &BodyShape::chest, true},
    {"hips", kBreadthRange, &BodyShape::hips, true},
    {"arm_length", kArmLengthRange, &BodyShape::arm_length, false},
    {"leg_length", kLegLengthRange, &BodyShape::leg_length, false},
};
// Its skin, where it differs from [physics]'s, and its images' levels (defaults: Subject's).
constexpr NumberKey<Subject> kSubjectKeys[] = {
    {"skin_emissivity", kSkinEmissivityRange.lo, kSkinEmissivityRange.hi, &Subject::skin_emissivity},
    {"skin_temperature", kSkinTemperatureRange.lo, kSkinTemperatureRange.hi, &Subject::skin_temperature},
    {"mmw_level", 0, 255, nullptr, &Subject::mmw_level},
    {"ir_core", 0, 255, nullptr, &Subject::ir_core},
    {"ir_limb", 0, 255, nullptr, &Subject::ir_limb},
};

template <class T, size_t N>
std::vector<std::string_view> key_names(const NumberKey<T> (&keys)[N]) {
  std::vector<std::string_view> out;
  for (const NumberKey<T>& k : keys) out.push_back(k.key);
  return out;
}

// Reads `keys` of table `t` (field `f`) into `into`, in order. A key left out keeps the
// field's value unless `required` holds it (every key where `required` is empty).
template <class T, size_t N>
void read_keys(const Reader& rd, const toml::table& t, const std::string& f, const NumberKey<T> (&keys)[N], T& into,
               std::span<const char* const> required = {}, bool all_required = false) {
  for (const NumberKey<T>& k : keys) {
    const bool need = all_required || std::any_of(required.begin(), required.end(),
                                                  [&](const char* r) { return std::string_view(r) == k.key; });
    if (k.number) {
      into.*k.number = need ? rd.number(t, k.key, f, k.lo, k.hi) : rd.number(t, k.key, f, k.lo, k.hi, into.*k.number);
    } else {
      const auto lo = static_cast<long long>(k.lo), hi = static_cast<long long>(k.hi);
      into.*k.integer = need ? rd.integer(t, k.key, f, lo, hi) : rd.integer(t, k.key, f, lo, hi, into.*k.integer);
    }
    if (k.above) {
      const auto other = std::find_if(std::begin(keys), std::end(keys),
                                      [&](const NumberKey<T>& o) { return std::string_view(o.key) == k.above; });
      if (into.*k.number <= into.*other->number)
        rd.fail(&t, f + "." + k.key, "must be above " + f + "." + std::string(k.above));
    }
  }
}

std::string fnv1a_hex(std::string_view text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// [metal.physics]: the coil model of --model physics. Ranges keep every value physical
// and every computed signal finite.
void read_metal_physics(const Reader& rd, const toml::node* node, Catalogue& cat) {
  const std::string f = "metal.physics";
  const toml::table* t = node->as_table();
  if (!t) rd.fail(node, f, "expected a table");
  std::vector<std::string_view> known = key_names(kMetalPhysicsKeys);
  known.push_back("tx_panel");
  for (const ZoneArrayKey& k : kMetalZoneKeys) known.push_back(k.key);
  known.push_back("polarizability");
  io::reject_unknown_keys(*t, known, rd.file, f);
  MetalPhysics& mp = cat.metal_physics;
  mp.present = true;
  read_keys(rd, *t, f, kMetalPhysicsKeys, mp, {}, true);
  {
    const toml::node* n = rd.need(*t, "tx_panel", f + ".tx_panel");
    const toml::array* a = n->as_array();
    if (!a || a->size() != static_cast<size_t>(cat.zones))
      rd.fail(n, f + ".tx_panel", "expected an array of " + std::to_string(cat.zones) + " panels, \"a\" or \"b\"");
    for (size_t z = 0; z < a->size(); ++z) {
      const toml::node* e = a->get(z);
      const std::string ez = f + ".tx_panel[" + std::to_string(z) + "]";
      if (!e->is_string() || (e->as_string()->get() != "a" && e->as_string()->get() != "b"))
        rd.fail(e, ez, "expected \"a\" (x < 0, the subject's right) or \"b\"");
      mp.tx_side.push_back(e->as_string()->get() == "a" ? -1 : 1);
    }
  }
  for (const ZoneArrayKey& k : kMetalZoneKeys) mp.*k.values = rd.numbers(*t, k.key, f, cat.zones, k.lo, k.hi);
  const toml::node* pn = rd.need(*t, "polarizability", f + ".polarizability");
  const toml::table* pol = pn->as_table();
  if (!pol) rd.fail(pn, f + ".polarizability", "expected a table of category = cm^3");
  for (const auto& [key, value] : *pol) {
    bool known = false;
    for (const std::string& c : cat.metal_categories) known |= (c == key.str());
    if (!known) rd.fail(&value, f + ".polarizability." + std::string(key.str()), "not one of metal.categories");
  }
  for (const std::string& c : cat.metal_categories)
    mp.polarizability.push_back(rd.number(*pol, c, f + ".polarizability", 0.0, 1e6));
}

// [[views]]: the portal's camera views, in output order (scene/sensor.h).
void read_views(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::array& views = rd.array_of_tables(root, "views");
  // Views are counted in the pixel noise stream's element (PS_PIXEL_NOISE_VIEW_SHIFT) and a
  // subject's base images: 16 is far more than any portal has.
  if (views.empty() || views.size() > 16) rd.fail(&views, "views", "expected 1 to 16 views");
  for (size_t i = 0; i < views.size(); ++i) {
    const toml::table& t = *views.get(i)->as_table();
    const std::string f = "views[" + std::to_string(i + 1) + "]";
    io::reject_unknown_keys(t, {"name", "camera", "side", "size", "field", "pooled", "netd", "raw"}, rd.file, f);
    Sensor s;
    s.name = rd.string(t, "name", f);
    const bool name_ok =
        !s.name.empty() && s.name.size() <= 32 && std::all_of(s.name.begin(), s.name.end(), [](char c) {
          return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
        });
    // It names files, columns, data sets and Python keys.
    if (!name_ok) rd.fail(t.get("name"), f + ".name", "\"" + s.name + "\": expected 1 to 32 of a-z, 0-9 and _");
    if (cat.sensor_index(s.name) >= 0) rd.fail(t.get("name"), f + ".name", "\"" + s.name + "\" is named twice");
    const std::string camera = rd.string(t, "camera", f);
    const CameraKind* kind = camera_kind_named(camera);
    if (!kind) rd.fail(t.get("camera"), f + ".camera", "expected " + camera_kind_names() + ", got \"" + camera + "\"");
    s.camera = kind->camera;
    const std::string side = rd.string(t, "side", f, "front");
    if (side != "front" && side != "back")
      rd.fail(t.get("side"), f + ".side", "expected \"front\" or \"back\", got \"" + side + "\"");
    s.side = side == "back" ? Side::back : Side::front;
    const std::vector<int> size = rd.ints(rd.need(t, "size", f + ".size"), f + ".size", 2, 1, 4096);
    s.width = size[0];
    s.height = size[1];
    const std::string ff = f + ".field";
    const toml::node* fn = rd.need(t, "field", ff);
    const toml::array* fa = fn->as_array();
    if (!fa || fa->size() != 4) rd.fail(fn, ff, "expected [x, y, width, height] in the portal's 200 x 400 field");
    std::array<double, 4> v{};
    for (size_t k = 0; k < 4; ++k)
      v[k] = rd.number(fa->get(k), ff + "[" + std::to_string(k) + "]", k < 2 ? -kFieldHeight : 1.0, kFieldHeight);
    s.field = {v[0], v[1], v[2], v[3]};
    if (const toml::node* pn = t.get("pooled")) {
      if (!pn->is_boolean()) rd.fail(pn, f + ".pooled", "expected true or false");
      s.pooled = pn->as_boolean()->get();
    }
    // The camera's own numbers where they differ from the run's knobs (the knobs' ranges).
    if (t.get("netd")) s.netd = rd.number(t, "netd", f, 0.0, kind->netd_max);
    if (const toml::node* rn = t.get("raw")) {
      if (!kind->raw_grid)
        rd.fail(rn, f + ".raw", std::string("a raw grid is an MMW camera's; this view's camera is ") + kind->name);
      const std::vector<int> raw = rd.ints(rn, f + ".raw", 2, 1, 4096);
      if (raw[0] > s.width || raw[1] > s.height)
        rd.fail(rn, f + ".raw",
                std::to_string(raw[0]) + "x" + std::to_string(raw[1]) + " is finer than the view (" +
                    std::to_string(s.width) + "x" + std::to_string(s.height) + ")");
      s.raw = std::array<int, 2>{raw[0], raw[1]};
    }
    cat.sensors.push_back(std::move(s));
  }
}

// [images]: the compositing settings.
void read_images(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::node* imgs_node = rd.need(root, "images", "images");
  const toml::table* imgs = imgs_node->as_table();
  if (!imgs) rd.fail(imgs_node, "images", "expected a table");
  for (const char* moved : {"mmw_width", "mmw_height", "ir_width", "ir_height"})
    if (const toml::node* n = imgs->get(moved))
      rd.fail(n, std::string("images.") + moved, "the views' sizes are [[views]] entries now (size = [WIDTH, HEIGHT])");
  io::reject_unknown_keys(*imgs, key_names(kImagesKeys), rd.file, "images");
  read_keys(rd, *imgs, "images", kImagesKeys, cat.images, kImagesRequired);
}

// [[regions]]: each with its rectangle in every view that sees it.
void read_regions(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::array& regions = rd.array_of_tables(root, "regions");
  if (regions.empty() || regions.size() > static_cast<size_t>(kMaxRegions))
    rd.fail(&regions, "regions",
            "expected 1 to " + std::to_string(kMaxRegions) + " regions, found " + std::to_string(regions.size()));
  cat.regions.resize(regions.size());
  for (size_t i = 0; i < regions.size(); ++i) {
    const toml::table& t = *regions.get(i)->as_table();
    const std::string f = "regions[" + std::to_string(i + 1) + "]";
    for (const char* moved : {"id", "view", "mmw", "ir"})
      if (const toml::node* n = t.get(moved))
        rd.fail(n, f + "." + moved,
                "regions are numbered in their order and placed by rects = { VIEW = [x, y, w, h], ... } now");
    io::reject_unknown_keys(t, {"name", "rects"}, rd.file, f);
    Region& r = cat.regions[i];
    r.id = static_cast<int>(i + 1);
    r.name = rd.string(t, "name", f);
    // It labels evaluate's per-region report and the page's lists.
    for (size_t j = 0; j < i; ++j)
      if (cat.regions[j].name == r.name) rd.fail(t.get("name"), f + ".name", "\"" + r.name + "\" is named twice");
    const toml::node* rn = rd.need(t, "rects", f + ".rects");
    const toml::table* rects = rn->as_table();
    if (!rects || rects->empty()) rd.fail(rn, f + ".rects", "expected a table of view = [x, y, w, h], at least one");
    for (const auto& [key, value] : *rects) {
      const std::string rf = f + ".rects." + std::string(key.str());
      const int k = cat.sensor_index(key.str());
      if (k < 0) rd.fail(&value, rf, "not one of the catalogue's [[views]]");
      Sensor& view = cat.sensors[k];
      view.rects[i] = rd.rect(&value, rf, view.width, view.height);
      view.region_mask |= 1u << i;
    }
  }
}

// [metal]: the zones, the categories, each category's influence table per region and
// [metal.physics].
void read_metal(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::node* metal_node = rd.need(root, "metal", "metal");
  const toml::table* metal = metal_node->as_table();
  if (!metal) rd.fail(metal_node, "metal", "expected a table");
  io::reject_unknown_keys(*metal, {"zones", "categories", "influence", "physics"}, rd.file, "metal");
  {
    cat.zones = static_cast<int>(rd.integer(rd.need(*metal, "zones", "metal.zones"), "metal.zones", 1, kMaxZones));
    const toml::node* cn = rd.need(*metal, "categories", "metal.categories");
    const toml::array* ca = cn->as_array();
    if (!ca || ca->empty()) rd.fail(cn, "metal.categories", "expected a non-empty array of names");
    for (size_t i = 0; i < ca->size(); ++i) {
      const toml::node* e = ca->get(i);
      if (!e->is_string()) rd.fail(e, "metal.categories[" + std::to_string(i) + "]", "expected a string");
      cat.metal_categories.push_back(e->as_string()->get());
    }
    const toml::node* inf_node = rd.need(*metal, "influence", "metal.influence");
    const toml::table* inf = inf_node->as_table();
    if (!inf) rd.fail(inf_node, "metal.influence", "expected a table");
    for (const auto& [key, node] : *inf) {
      bool known = false;
      for (const std::string& c : cat.metal_categories) known |= (c == key.str());
      if (!known) rd.fail(&node, "metal.influence." + std::string(key.str()), "not one of metal.categories");
    }
    for (const std::string& c : cat.metal_categories) {
      const std::string f = "metal.influence." + c;
      const toml::node* rows_node = rd.need(*inf, c, f);
      const toml::array* rows = rows_node->as_array();
      if (!rows || rows->size() != cat.regions.size())
        rd.fail(rows_node, f, "expected " + std::to_string(cat.regions.size()) + " rows, one per region");
      std::vector<std::vector<int>> table;
      for (int r = 0; r < cat.region_count(); ++r)
        table.push_back(rd.ints(rows->get(r), f + "[region " + std::to_string(r + 1) + "]", cat.zones, 0, 199));
      cat.influence.push_back(std::move(table));
    }
    if (const toml::node* pn = metal->get("physics")) read_metal_physics(rd, pn, cat);
  }
}

// [[subjects]]: the catalogue's bodies.
void read_subjects(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::array& subjects = rd.array_of_tables(root, "subjects");
  if (subjects.empty() || subjects.size() > 255) rd.fail(&subjects, "subjects", "expected 1 to 255 subjects");
  std::vector<std::string_view> known{"name"};
  for (const ShapeKey& k : kShapeKeys) known.push_back(k.key);
  known.push_back("pose");
  for (std::string_view k : key_names(kSubjectKeys)) known.push_back(k);
  known.insert(known.end(), {"base_zones", "images"});
  for (size_t i = 0; i < subjects.size(); ++i) {
    const toml::table& t = *subjects.get(i)->as_table();
    const std::string f = "subjects[" + std::to_string(i + 1) + "]";
    io::reject_unknown_keys(t, known, rd.file, f);
    Subject s;
    s.name = rd.string(t, "name", f);
    BodyShape& b = s.shape;
    // Breadths default to the build, so a subject that gives only `build` is drawn as before.
    for (const ShapeKey& k : kShapeKeys)
      b.*k.field = rd.number(t, k.key, f, k.range.lo, k.range.hi, k.defaults_to_build ? b.build : 1.0);
    b.places_follow_width = t.contains("shoulders") || t.contains("chest") || t.contains("hips");
    const std::string pose = rd.string(t, "pose", f, std::string("arms-down"));
    if (!parse_pose(pose, b.pose))
      rd.fail(t.get("pose"), f + ".pose", "\"" + pose + "\" is not a pose (arms-down, arms-raised, arms-out)");
    read_keys(rd, t, f, kSubjectKeys, s);
    s.base_zones = rd.ints(rd.need(t, "base_zones", f + ".base_zones"), f + ".base_zones", cat.zones, 1, 200);
    if (const toml::node* in = t.get("images")) {
      const toml::table* it = in->as_table();
      if (!it) rd.fail(in, f + ".images", "expected a table of view = \"file\"");
      for (const auto& [key, value] : *it) {
        if (cat.sensor_index(key.str()) < 0)
          rd.fail(&value, f + ".images." + std::string(key.str()), "not one of the catalogue's [[views]]");
        s.images.emplace(std::string(key.str()), rd.image(*it, std::string(key.str()), f + ".images"));
      }
    }
    // Objects move with the stature and the legs; an image file's body would not.
    for (const auto& [key, value] : {std::pair{"height", b.height}, std::pair{"leg_length", b.leg_length}})
      if (value != 1.0 && !s.images.empty())
        rd.fail(t.get(key), f + "." + key,
                "only a procedural body can be drawn at another height; this subject names image files (images)");
    cat.subjects.push_back(std::move(s));
  }
}

// [physics]: optional; the physics model's scene and sensor.
void read_physics(const Reader& rd, const toml::table& root, Catalogue& cat) {
  if (const toml::node* pn = root.get("physics")) {
    const toml::table* pt = pn->as_table();
    if (!pt) rd.fail(pn, "physics", "expected a table");
    io::reject_unknown_keys(*pt, key_names(kPhysicsKeys), rd.file, "physics");
    read_keys(rd, *pt, "physics", kPhysicsKeys, cat.physics);
  }
}

// [[materials]]: optional; the physics model's objects' materials.
void read_materials(const Reader& rd, const toml::table& root, Catalogue& cat) {
  if (root.get("materials")) {
    const toml::array& mats = rd.array_of_tables(root, "materials");
    if (mats.size() > 1000) rd.fail(&mats, "materials", "expected at most 1000 materials");
    for (size_t i = 0; i < mats.size(); ++i) {
      const toml::table& t = *mats.get(i)->as_table();
      const std::string f = "materials[" + std::to_string(i + 1) + "]";
      io::reject_unknown_keys(t, {"name", "emissivity", "warm_minutes", "source"}, rd.file, f);
      Material m;
      m.name = rd.string(t, "name", f);
      for (const Material& other : cat.materials)
        if (other.name == m.name) rd.fail(t.get("name"), f + ".name", "\"" + m.name + "\" is named twice");
      read_keys(rd, t, f, kMaterialKeys, m, {}, true);
      rd.string(t, "source", f);  // every value says where it comes from
      cat.materials.push_back(m);
    }
  }
}

// [[objects]]' keys, each camera kind's in the registry's order: <kind>_level, <kind>, then
// <kind>_h and <kind>_v (the order "did you mean" prefers among equally near keys).
const std::vector<std::string_view>& object_keys() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> k{"name", "aliases", "class", "family", "material", "metal", "shape", "size"};
    for (const CameraKind* kind : camera_kinds()) k.push_back(kind->name + std::string("_level"));
    k.push_back("variants");
    for (const CameraKind* kind : camera_kinds()) k.push_back(kind->name);
    for (const CameraKind* kind : camera_kinds())
      for (const char* sfx : {"_h", "_v"}) k.push_back(kind->name + std::string(sfx));
    k.push_back("metal_anisotropy");
    return k;
  }();
  static const std::vector<std::string_view> keys(names.begin(), names.end());
  return keys;
}

// [[objects]]: after [metal] and [[materials]], which they name.
void read_objects(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::array& objects = rd.array_of_tables(root, "objects");
  if (objects.empty() || objects.size() > 1000) rd.fail(&objects, "objects", "expected 1 to 1000 objects");
  for (size_t i = 0; i < objects.size(); ++i) {
    const toml::table& t = *objects.get(i)->as_table();
    const std::string f = "objects[" + std::to_string(i + 1) + "]";
    io::reject_unknown_keys(t, object_keys(), rd.file, f);
    Object o;
    o.name = rd.string(t, "name", f);
    for (const char* reserved : {"", "none", "all", "class", "family"})  // words of pools and rules
      if (normalise_name(o.name) == reserved)
        rd.fail(t.get("name"), f + ".name", "\"" + o.name + "\" cannot name an object");
    if (const toml::node* an = t.get("aliases")) {
      const toml::array* a = an->as_array();
      if (!a) rd.fail(an, f + ".aliases", "expected an array of strings");
      for (size_t k = 0; k < a->size(); ++k) {
        if (!a->get(k)->is_string()) rd.fail(a->get(k), f + ".aliases[" + std::to_string(k) + "]", "expected a string");
        o.aliases.push_back(a->get(k)->as_string()->get());
      }
    }
    for (const std::string& n : [&] {
           std::vector<std::string> all{o.name};
           all.insert(all.end(), o.aliases.begin(), o.aliases.end());
           return all;
         }()) {
      if (cat.find_object(n) >= 0)
        rd.fail(&t, f + ".name", "\"" + n + "\" already names " + cat.objects[cat.find_object(n)].name);
    }
    for (auto [key, into] : {std::pair{"class", &o.object_class}, std::pair{"family", &o.family}}) {
      *into = rd.string(t, key, f, "");
      if (t.get(key) && (normalise_name(*into).empty() || into->size() > 64 ||
                         into->find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos))
        rd.fail(t.get(key), f + "." + key,
                "expected a name of a-z, 0-9, '-' and '_' (at most 64), got \"" + *into + "\"");
    }
    o.material = rd.string(t, "material", f, "");
    if (!cat.materials.empty()) {
      for (size_t m = 0; m < cat.materials.size(); ++m)
        if (cat.materials[m].name == o.material) o.material_id = static_cast<int>(m);
      if (o.material_id < 0)
        rd.fail(t.get("material") ? t.get("material") : &t, f + ".material",
                "\"" + o.material + "\" is not one of the catalogue's [[materials]]");
    }
    const std::string metal_name = rd.string(t, "metal", f);
    o.metal = -1;
    for (size_t c = 0; c < cat.metal_categories.size(); ++c)
      if (cat.metal_categories[c] == metal_name) o.metal = static_cast<int>(c);
    if (o.metal < 0) rd.fail(t.get("metal"), f + ".metal", "\"" + metal_name + "\" is not in metal.categories");
    o.shape = rd.string(t, "shape", f);
    const std::vector<int> size = rd.ints(rd.need(t, "size", f + ".size"), f + ".size", 2, 1, 4096);
    o.width = size[0];
    o.height = size[1];
    o.metal_anisotropy = rd.number(t, "metal_anisotropy", f, 1.0, 1000.0, 1.0);
    for (const CameraKind* kind : camera_kinds())
      o.levels.push_back(rd.integer(t, kind->name + std::string("_level"), f, 0, 255));
    std::vector<std::string> codes;
    if (const toml::node* vn = t.get("variants")) {
      const toml::array* va = vn->as_array();
      if (!va || va->empty()) rd.fail(vn, f + ".variants", "expected a non-empty array such as [\"h\", \"v\"]");
      for (size_t k = 0; k < va->size(); ++k) {
        const toml::node* e = va->get(k);
        const std::string vf = f + ".variants[" + std::to_string(k) + "]";
        if (!e->is_string()) rd.fail(e, vf, "expected \"h\" or \"v\"");
        const std::string code = e->as_string()->get();
        if (code != "h" && code != "v") rd.fail(e, vf, "expected \"h\" or \"v\", got \"" + code + "\"");
        for (const std::string& c : codes)
          if (c == code) rd.fail(e, vf, "variant \"" + code + "\" listed twice");
        codes.push_back(code);
      }
    } else {
      codes.push_back("");
    }
    bool file_images = false;
    for (const CameraKind* kind : camera_kinds())
      for (const char* sfx : {"", "_h", "_v"}) file_images |= t.get(kind->name + std::string(sfx)) != nullptr;
    if (!is_procedural_shape(o.shape) && !file_images)
      rd.fail(t.get("shape"), f + ".shape", "unknown shape \"" + o.shape + "\" and no image files given");
    if (codes.size() > 1)
      for (const CameraKind* kind : camera_kinds())
        if (const std::string key = kind->name; t.get(key))
          rd.fail(t.get(key), f + "." + key,
                  rd.image(t, key, f).path + ": this object has several drawings; name one file per drawing (" + key +
                      "_h, " + key + "_v)");
    o.first_variant = static_cast<int>(cat.variant_list.size());
    for (size_t k = 0; k < codes.size(); ++k) {
      Variant v;
      v.code = codes[k];
      const std::string sfx = v.code.empty() ? "" : "_" + v.code;
      for (const CameraKind* kind : camera_kinds()) v.images.push_back(rd.image(t, kind->name + sfx, f));
      if (codes.size() == 1)  // one drawing may be given without its code
        for (size_t c = 0; c < v.images.size(); ++c)
          if (v.images[c].path.empty()) v.images[c] = rd.image(t, camera_kinds()[c]->name, f);
      o.variants.push_back(v);
      cat.variant_list.push_back({static_cast<int>(cat.objects.size()), static_cast<int>(k)});
    }
    if (cat.variant_list.size() > 30000) rd.fail(&t, f, "too many object variants (at most 30000)");
    cat.objects.push_back(std::move(o));
  }
}

// default_pool: object names, after the objects it names.
void read_default_pool(const Reader& rd, const toml::table& root, Catalogue& cat) {
  if (const toml::node* dp = root.get("default_pool")) {
    const toml::array* a = dp->as_array();
    if (!a || a->empty()) rd.fail(dp, "default_pool", "expected a non-empty array of object names");
    for (size_t k = 0; k < a->size(); ++k) {
      const std::string pf = "default_pool[" + std::to_string(k + 1) + "]";
      if (!a->get(k)->is_string()) rd.fail(a->get(k), pf, "expected an object's name");
      const int o = cat.find_object(a->get(k)->as_string()->get());
      if (o < 0) rd.fail(a->get(k), pf, "\"" + a->get(k)->as_string()->get() + "\" is not one of the [[objects]]");
      if (std::find(cat.default_pool.begin(), cat.default_pool.end(), o) != cat.default_pool.end())
        rd.fail(a->get(k), pf, "\"" + cat.objects[o].name + "\" is listed twice");
      cat.default_pool.push_back(o);
    }
  } else {
    for (size_t o = 0; o < cat.objects.size(); ++o) cat.default_pool.push_back(static_cast<int>(o));
  }
}

// [[noise]]: the thesis's MMW noise patterns.
void read_noise(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::array& noise = rd.array_of_tables(root, "noise");
  if (noise.empty() || noise.size() > 255) rd.fail(&noise, "noise", "expected 1 to 255 noise patterns");
  for (size_t i = 0; i < noise.size(); ++i) {
    const toml::table& t = *noise.get(i)->as_table();
    const std::string f = "noise[" + std::to_string(i + 1) + "]";
    io::reject_unknown_keys(t, {"name", "gain", "image"}, rd.file, f);
    NoisePattern p;
    p.name = rd.string(t, "name", f);
    p.gain = rd.number(t, "gain", f, 0.0, 100.0, 1.0);
    p.image = rd.image(t, "image", f);
    if (p.image.path.empty() && i >= static_cast<size_t>(kProceduralNoisePatterns))
      rd.fail(&t, f,
              "only the first " + std::to_string(kProceduralNoisePatterns) +
                  " noise patterns have procedural defaults; give an image");
    cat.noise.push_back(std::move(p));
  }
}

// Each view draws the objects at its scale: none larger than an image may be (4096 a side,
// as a view or an object's catalogue size). After derive_view, which sets the scales.
void check_drawn_sizes(const Reader& rd, const toml::table& root, Catalogue& cat) {
  const toml::array& views = *root.get("views")->as_array();
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& s = cat.sensors[k];
    for (const Object& o : cat.objects) {
      const double longest = std::max(o.width, o.height);
      if (std::lround(longest * s.jitter_scale_x) > 4096 || std::lround(longest * s.jitter_scale_y) > 4096)
        rd.fail(views.get(k)->as_table()->get("field"), "views[" + std::to_string(k + 1) + "].field",
                "the view draws " + o.name + " (" + std::to_string(o.width) + "x" + std::to_string(o.height) +
                    " field units) more than 4096 pixels long; give the view a larger field or a smaller size");
    }
  }
}

}  // namespace

const ImageSource& Subject::image(std::string_view view) const {
  static const ImageSource procedural;
  const auto it = images.find(view);
  return it == images.end() ? procedural : it->second;
}

std::array<double, 9> Catalogue::polarizability(int variant_id) const {
  // Along the drawing's long side, as long_side lays it: across (x) or up (z).
  const bool up = long_side(variant_id)[0] == 0.0;
  return polarizability(variant_id, up ? std::array<double, 3>{0, 0, 1} : std::array<double, 3>{1, 0, 0});
}

std::array<double, 9> Catalogue::polarizability(int variant_id, const std::array<double, 3>& u) const {
  const Object& o = object_of(variant_id);
  const double m = metal_physics.polarizability.empty() ? 0.0 : metal_physics.polarizability[o.metal];
  const double a = o.metal_anisotropy;
  const double across = m * 3.0 / (a + 2.0);
  // Diagonal across (1 - u_i^2) + across a u_i^2, off the diagonal across (a - 1) u_i u_j:
  // along an axis, exactly across and across a.
  std::array<double, 9> t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      t[i * 3 + j] =
          i == j ? across * (1.0 - u[i] * u[i]) + across * a * (u[i] * u[i]) : across * (a - 1.0) * u[i] * u[j];
  return t;
}

std::array<double, 2> Catalogue::long_side(int variant_id) const {
  const Object& o = object_of(variant_id);
  const double scale = metres_per_field_unit();
  const bool turned = variant(variant_id).code == "v";
  const int w = turned ? o.height : o.width, h = turned ? o.width : o.height;
  return w >= h ? std::array<double, 2>{w * scale, 0.0} : std::array<double, 2>{0.0, h * scale};
}

std::string normalise_name(std::string_view name) {
  std::string out;
  for (unsigned char c : name)
    if (std::isalnum(c)) out.push_back(static_cast<char>(std::tolower(c)));
  return out;
}

std::string Catalogue::variant_name(int variant_id) const {
  const Object& o = object_of(variant_id);
  const Variant& v = variant(variant_id);
  return v.code.empty() ? o.name : o.name + ":" + v.code;
}

std::string Catalogue::object_names() const {
  std::string names;
  for (const Object& o : objects) names += (names.empty() ? "" : ", ") + o.name;
  return names;
}

int Catalogue::find_object(std::string_view name) const {
  const std::string key = normalise_name(name);
  if (key.empty()) return -1;
  for (size_t i = 0; i < objects.size(); ++i) {
    if (normalise_name(objects[i].name) == key) return static_cast<int>(i);
    for (const std::string& a : objects[i].aliases)
      if (normalise_name(a) == key) return static_cast<int>(i);
  }
  return -1;
}

Catalogue parse_catalogue(std::string_view text, const std::string& source_name, const std::string& base_dir,
                          const std::string& assets_dir) {
  Reader rd{source_name, base_dir, assets_dir};
  const toml::table root = io::parse_toml(text, source_name);
  io::reject_unknown_keys(root,
                          {"format", "default_pool", "images", "views", "metal", "subjects", "regions", "objects",
                           "noise", "physics", "materials"},
                          source_name, "");
  Catalogue cat;
  cat.source = source_name;
  cat.hash = fnv1a_hex(text);

  if (const toml::node* f = root.get("format")) rd.integer(f, "format", 1, 1);

  read_images(rd, root, cat);
  read_views(rd, root, cat);
  read_regions(rd, root, cat);
  // [metal] before the objects (they refer to its categories) and the subjects (their
  // base_zones are one per zone); after the regions (an influence row per region).
  read_metal(rd, root, cat);
  read_subjects(rd, root, cat);
  read_physics(rd, root, cat);
  read_materials(rd, root, cat);
  read_objects(rd, root, cat);
  read_default_pool(rd, root, cat);
  read_noise(rd, root, cat);
  for (Sensor& view : cat.sensors) derive_view(cat, view);
  check_drawn_sizes(rd, root, cat);
  return cat;
}

Catalogue load_catalogue(const std::string& path, const std::string& assets_dir) {
  const std::string text = io::read_file(path, "catalogue file", io::kMaxTextBytes);
  const std::string dir = std::filesystem::absolute(path).parent_path().string();
  return parse_catalogue(text, path, dir, assets_dir);
}

Catalogue default_catalogue(const std::string& assets_dir) {
  return parse_catalogue(embedded::default_catalogue, "<built-in catalogue>", "", assets_dir);
}

}  // namespace portalsim
