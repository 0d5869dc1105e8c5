#include "plan/knobs.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <variant>

#include "base/error.h"

namespace portalsim {

namespace {

std::string format_number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// A knob of numbers within [lo, hi] (integer, number; each side of a grid).
Knob bounded(KnobKind kind, std::string key, std::string def, double lo, double hi, std::string unit, std::string help,
             std::function<void(Plan&, double)> set, std::function<nlohmann::json(const Plan&)> get) {
  return Knob{.key = std::move(key),
              .def = std::move(def),
              .kind = kind,
              .min = lo,
              .max = hi,
              .unit = std::move(unit),
              .help = std::move(help),
              .set = std::move(set),
              .get = std::move(get)};
}

Knob integer(std::string key, std::string def, int lo, int hi, std::string unit, std::string help,
             std::function<void(Plan&, double)> set, std::function<nlohmann::json(const Plan&)> get) {
  return bounded(KnobKind::integer, std::move(key), std::move(def), lo, hi, std::move(unit), std::move(help),
                 std::move(set), std::move(get));
}

Knob number(std::string key, std::string def, double lo, double hi, std::string unit, std::string help,
            std::function<void(Plan&, double)> set, std::function<nlohmann::json(const Plan&)> get) {
  return bounded(KnobKind::number, std::move(key), std::move(def), lo, hi, std::move(unit), std::move(help),
                 std::move(set), std::move(get));
}

Knob on_off(std::string key, std::string def, std::string help, bool fidelity, std::function<void(Plan&, double)> set,
            std::function<nlohmann::json(const Plan&)> get) {
  return Knob{.key = std::move(key),
              .def = std::move(def),
              .kind = KnobKind::on_off,
              .min = 0,
              .max = 1,
              .choices = {"on", "off"},
              .help = std::move(help),
              .fidelity = fidelity,
              .set = std::move(set),
              .get = std::move(get)};
}

Knob grid(std::string key, std::string def, int lo, int hi, std::string unit, std::string help,
          std::function<void(Plan&, double)> set, std::function<nlohmann::json(const Plan&)> get) {
  return bounded(KnobKind::grid, std::move(key), std::move(def), lo, hi, std::move(unit), std::move(help),
                 std::move(set), std::move(get));
}

Knob choice(std::string key, std::string def, std::vector<std::string> choices, std::string help, bool fidelity,
            bool identity, std::function<void(Plan&, double)> set, std::function<nlohmann::json(const Plan&)> get) {
  return Knob{.key = std::move(key),
              .def = std::move(def),
              .kind = KnobKind::choice,
              .choices = std::move(choices),
              .help = std::move(help),
              .fidelity = fidelity,
              .identity = identity,
              .set = std::move(set),
              .get = std::move(get)};
}

// A range A..B of numbers within [lo, hi]; `symmetric`: one number X means -X..X.
Knob range(std::string key, std::string def, double lo, double hi, bool symmetric, std::string unit, std::string help,
           std::function<void(Plan&, double, double)> set, std::function<std::pair<double, double>(const Plan&)> get) {
  Knob k{.key = std::move(key),
         .def = std::move(def),
         .kind = KnobKind::range,
         .min = lo,
         .max = hi,
         .unit = std::move(unit),
         .help = std::move(help),
         .symmetric = symmetric,
         .set_range = std::move(set)};
  k.get = [get = std::move(get), symmetric](const Plan& p) -> nlohmann::json {
    const auto [a, b] = get(p);
    if (symmetric ? a == -b : a == b) return format_number(b);
    return format_number(a) + ".." + format_number(b);
  };
  return k;
}

// `k`, an integer or number knob, drawn per scenario where given A..B (Knob::drawn): element
// `element`, setting `field` (DrawnKnob).
template <class T>
Knob drawable(Knob k, unsigned element, T ModelSettings::*field) {
  k.drawn = static_cast<int>(element);
  k.draws = {{.element = element, .key = k.key, .field = field}};
  k.get = [get = std::move(k.get), element](const Plan& p) -> nlohmann::json {
    const DrawnRange& d = p.model.drawn[element];
    if (d.varies()) return format_number(d.lo) + ".." + format_number(d.hi);
    return get(p);
  };
  return k;
}

// `k`, a range knob, with its ends drawn per scenario where given L1..L2/H1..H2
// (Knob::drawn_ends): elements `lo` and `hi`, keyed as the knob's key and _lo, _hi, setting
// `lo_field` and `hi_field`. A fixed end's drawn range is that one value.
Knob drawable_ends(Knob k, unsigned lo, unsigned hi, double ModelSettings::*lo_field, double ModelSettings::*hi_field) {
  k.drawn_ends = {static_cast<int>(lo), static_cast<int>(hi)};
  k.draws = {{.element = lo, .key = k.key + "_lo", .field = lo_field},
             {.element = hi, .key = k.key + "_hi", .field = hi_field}};
  k.get = [get = std::move(k.get), lo, hi](const Plan& p) -> nlohmann::json {
    const DrawnRange &a = p.model.drawn[lo], &b = p.model.drawn[hi];
    if (!a.varies() && !b.varies()) return get(p);
    const auto end = [](const DrawnRange& d) {
      return d.varies() ? format_number(d.lo) + ".." + format_number(d.hi) : format_number(d.lo);
    };
    return end(a) + "/" + end(b);
  };
  return k;
}

// `k`, whose value per scenario is a draw of its own from element `element` (the outfit:
// outfit_at; the raw grid: raw_grid_at), no number.
Knob drawn_by(Knob k, unsigned element) {
  k.draws = {{.element = element, .key = k.key}};
  return k;
}

std::vector<Knob> declare() {
  std::vector<Knob> k;
  // The sensor model (docs/model/thesis.md); defaults are the thesis's.
  k.push_back(choice(
      "model", "thesis", {"thesis", "physics"},
      "the sensor model: the thesis's composite (its exact examples), or the physically based one (apparent "
      "temperature, optics, raw grid, NETD; contact shadow in IR; coil fields and polarizability for metal)",
      false, true, [](Plan& p, double v) { p.model.model = static_cast<Model>(v); },
      [](const Plan& p) { return model_name(p.model.model); }));
  k.push_back(drawable(
      number(
          "illumination", "293", 1, 1000, "K",
          "physics: the temperature the scene reflects (the room indoors; about 50 K for a clear sky outdoors)",
          [](Plan& p, double v) { p.model.illumination = v; }, [](const Plan& p) { return p.model.illumination; }),
      PS_DRAWN_ILLUMINATION, &ModelSettings::illumination));
  k.push_back(drawable(number(
                           "netd", "3", 0, 100, "K", "physics: MMW sensor noise, rms per raw pixel (Vela 125: 3 K)",
                           [](Plan& p, double v) { p.model.netd = v; }, [](const Plan& p) { return p.model.netd; }),
                       PS_DRAWN_NETD, &ModelSettings::netd));
  k.push_back(grid(
      "mmw_raw", "28x28", 1, 4096, "raw pixels",
      "physics: the MMW camera's raw grid over each view, at most the view's size",
      [](Plan& p, double v) {
        p.model.raw_width = static_cast<int>(v) / 65536;
        p.model.raw_height = static_cast<int>(v) % 65536;
        p.model.raw_grids.clear();
      },
      [](const Plan& p) {
        if (!p.model.raw_grid_drawn())
          return std::to_string(p.model.raw_width) + "x" + std::to_string(p.model.raw_height);
        std::string list;
        for (const auto& [w, h] : p.model.raw_grids) {
          if (!list.empty()) list += ',';
          list.append(std::to_string(w)).append(1, 'x').append(std::to_string(h));
        }
        return list;
      }));
  k.back() = drawn_by(std::move(k.back()), PS_DRAWN_MMW_RAW);
  k.back().set_list = [](Plan& p, const std::vector<double>& grids) {
    p.model.raw_grids.clear();
    for (const double v : grids)
      p.model.raw_grids.push_back({static_cast<int>(v) / 65536, static_cast<int>(v) % 65536});
  };
  k.push_back(drawable(
      number(
          "worn_minutes", "5", 0, 1440, "minutes",
          "physics: how long the objects have been carried; they warm from the room towards the skin",
          [](Plan& p, double v) { p.model.worn_minutes = v; }, [](const Plan& p) { return p.model.worn_minutes; }),
      PS_DRAWN_WORN_MINUTES, &ModelSettings::worn_minutes));
  {
    Knob c = choice(
        "clothing", "catalogue", {kClothingNames.begin(), kClothingNames.end()},
        "physics: what the subjects wear: the catalogue's one clothing, or per scenario an outfit of layers of "
        "sourced fabrics (docs/model/clothing.md): random (none, shirt, sweater, jacket or coat, each alike), or "
        "one of those, its fabrics drawn",
        false, true, [](Plan& p, double v) { p.model.clothing = static_cast<Clothing>(v); },
        [](const Plan& p) { return kClothingNames[static_cast<size_t>(p.model.clothing)]; });
    c.omit_default = true;
    k.push_back(drawn_by(std::move(c), PS_DRAWN_CLOTHING));
  }
  {
    Knob f = drawable(number(
                          "clothing_folds", "0", 0, 1, "of the fold pattern",
                          "physics: under a drawn outfit, the share of the outer garment's fold and seam pattern "
                          "where it lies doubled, in both cameras (docs/model/clothing.md); 0: smooth layers",
                          [](Plan& p, double v) { p.model.clothing_folds = v; },
                          [](const Plan& p) { return p.model.clothing_folds; }),
                      PS_DRAWN_CLOTHING_FOLDS, &ModelSettings::clothing_folds);
    f.omit_default = true;
    k.push_back(std::move(f));
  }
  // The MMW camera's own processing (docs/model/physics-mmw.md).
  k.push_back(drawable(
      integer(
          "frames", "10", 1, 1000, "frames",
          "physics: raw MMW frames at the camera's 10 Hz averaged into each image, each with its own NETD draw "
          "(the fast tier: one draw of NETD/sqrt(frames))",
          [](Plan& p, double v) { p.model.frames = static_cast<int>(v); },
          [](const Plan& p) { return p.model.frames; }),
      PS_DRAWN_FRAMES, &ModelSettings::frames));
  {
    Knob w = range(
        "window", "290..302", 0, 1000, false, "K",
        "physics: the MMW display window, kelvin shown as gray 0 and 255: fixed, or auto, per image from the raw "
        "grid's 1st and 99th percentiles as a camera's automatic gain does",
        [](Plan& p, double a, double b) {
          p.model.window_auto = std::isnan(a);
          if (!p.model.window_auto) p.model.window_lo = a, p.model.window_hi = b;
        },
        [](const Plan& p) { return std::pair(p.model.window_lo, p.model.window_hi); });
    w.word = "auto";
    w.get = [get = w.get](const Plan& p) -> nlohmann::json { return p.model.window_auto ? "auto" : get(p); };
    k.push_back(drawable_ends(std::move(w), PS_DRAWN_WINDOW_LO, PS_DRAWN_WINDOW_HI, &ModelSettings::window_lo,
                              &ModelSettings::window_hi));
  }
  k.push_back(choice(
      "display_filter", "bilinear", {"bilinear", "bicubic"},
      "physics: how the MMW raw grid is interpolated to the view's pixels (bicubic: Keys' cubic convolution, "
      "a = -1/2)",
      false, true, [](Plan& p, double v) { p.model.display_filter = static_cast<DisplayFilter>(v); },
      [](const Plan& p) { return p.model.display_filter == DisplayFilter::bicubic ? "bicubic" : "bilinear"; }));
  k.push_back(number(
      "smooth", "0", 0, 50, "view pixels",
      "physics: sigma of a Gaussian smoothing of the MMW view after interpolation (0: none)",
      [](Plan& p, double v) { p.model.smooth = v; }, [](const Plan& p) { return p.model.smooth; }));
  k.push_back(drawable(
      number(
          "ir_netd", "0.05", 0, 10, "K", "physics: IR sensor noise, rms per pixel (thermal cameras: about 0.05 K)",
          [](Plan& p, double v) { p.model.ir_netd = v; }, [](const Plan& p) { return p.model.ir_netd; }),
      PS_DRAWN_IR_NETD, &ModelSettings::ir_netd));
  k.push_back(integer(
      "block", "10", 1, 65536, "pixels", "side of the averaged pixel blocks of the features (thesis 5.6)",
      [](Plan& p, double v) { p.model.block = static_cast<int>(v); }, [](const Plan& p) { return p.model.block; }));
  k.push_back(on_off(
      "pattern_noise", "on", "the thesis's MMW noise patterns, one over each object (thesis 4.2)", false,
      [](Plan& p, double v) { p.model.pattern_noise = v != 0; }, [](const Plan& p) { return p.model.pattern_noise; }));
  k.push_back(drawable(
      number(
          "pixel_noise", "0", 0, 1000, "gray levels", "per-pixel Gaussian sensor noise sigma (MMW and IR)",
          [](Plan& p, double v) { p.model.pixel_sigma = v; }, [](const Plan& p) { return p.model.pixel_sigma; }),
      PS_DRAWN_PIXEL_NOISE, &ModelSettings::pixel_sigma));
  k.push_back(drawable(
      integer(
          "metal_noise", "0", 0, 199, "counts", "metal detector noise: triangular integer noise of this half-width",
          [](Plan& p, double v) { p.model.metal_noise = static_cast<int>(v); },
          [](const Plan& p) { return p.model.metal_noise; }),
      PS_DRAWN_METAL_NOISE, &ModelSettings::metal_noise));
  k.push_back(choice(
      "placement", "integer", {"integer", "bilinear"},
      "sprite placement: whole pixels, or sub-pixel with bilinear sampling", false, true,
      [](Plan& p, double v) { p.model.bilinear = v != 0; },
      [](const Plan& p) { return p.model.bilinear ? "bilinear" : "integer"; }));
  k.push_back(number(
      "jitter", "0", 0, 1000, "pixels", "move each object by up to this much in x and y",
      [](Plan& p, double v) { p.model.jitter = v; }, [](const Plan& p) { return p.model.jitter; }));
  k.push_back(range(
      "rotate", "0", -180, 180, true, "degrees",
      "turn each object about its centre by an angle drawn uniformly from the range (X: -X..X), "
      "counter-clockwise in the image",
      [](Plan& p, double a, double b) {
        p.model.rotate_lo = a;
        p.model.rotate_hi = b;
      },
      [](const Plan& p) { return std::pair(p.model.rotate_lo, p.model.rotate_hi); }));
  k.push_back(range(
      "scale", "1", 0.1, 10, false, "",
      "scale each object about its centre by a factor drawn uniformly from the range (X: X..X)",
      [](Plan& p, double a, double b) {
        p.model.scale_lo = a;
        p.model.scale_hi = b;
      },
      [](const Plan& p) { return std::pair(p.model.scale_lo, p.model.scale_hi); }));
  k.push_back(on_off(
      "flip", "off", "mirror each object left to right with probability 1/2", false,
      [](Plan& p, double v) { p.model.flip = v != 0; }, [](const Plan& p) { return p.model.flip; }));
  k.push_back(choice(
      "palette", "ironbow", {"ironbow", "gray", "rainbow"},
      "how the IR temperature index is written as RGB: ironbow (the thesis's), gray (white hot), rainbow; "
      "the index itself is unchanged",
      false, true, [](Plan& p, double v) { p.palette = static_cast<procedural::PaletteName>(v); },
      [](const Plan& p) { return procedural::palette_name(p.palette); }));
  // The fidelity tiers' knobs (docs/model/tiers.md): each overrides --tier.
  k.push_back(choice(
      "precision", "", {"fp32", "fp64", "fixed16"},
      "the kernels' pixel arithmetic: fp32; fp64 with the reference's formulas; 8.8 fixed point in "
      "integers (alpha and noise gain quantised to 1/256)",
      true, true, [](Plan& p, double v) { p.fidelity.precision = static_cast<Precision>(v); },
      [](const Plan& p) { return precision_name(p.fidelity.precision); }));
  // Sparse and dense pooling agree to the bit, so pooling is not part of the identity.
  k.push_back(choice(
      "pooling", "", {"sparse", "dense"},
      "features-only runs from precomputed tables and overlap pixels (sparse), or by rendering "
      "every image and pooling it (dense); identical results",
      true, false, [](Plan& p, double v) { p.fidelity.pooling = static_cast<Pooling>(v); },
      [](const Plan& p) { return p.fidelity.pooling == Pooling::dense ? "dense" : "sparse"; }));
  k.push_back(on_off(
      "fast_math", "", "-cl-fast-relaxed-math for the kernel build", true,
      [](Plan& p, double v) { p.fidelity.fast_math = v != 0; }, [](const Plan& p) { return p.fidelity.fast_math; }));
  k.push_back(choice(
      "noise_model", "", {"per-pixel", "block-mean"},
      "in features-only runs with pixel noise: draw every pixel's noise, or give each mean over c "
      "pixels one draw of N(0, sigma^2/c) (ignores rounding and clipping of single pixels, keeps the sparse path); "
      "physics: draw the NETD per feature with the covariance per-raw-pixel noise gives",
      true, true, [](Plan& p, double v) { p.fidelity.noise = static_cast<NoiseModel>(v); },
      [](const Plan& p) { return p.fidelity.noise == NoiseModel::block_mean ? "block-mean" : "per-pixel"; }));
  k.push_back(choice(
      "noise_draw", "", {"box-muller", "irwin-hall"},
      "how the sensor noise is drawn: Box-Muller (thesis) or the quantile table (physics), both normal; or "
      "Irwin-Hall (both models), eight values to a Philox draw (two bytes summed, shaped by a quintic: sd 1, KS "
      "distance 0.0033 from the normal, none beyond 3.37 sd)",
      true, true, [](Plan& p, double v) { p.fidelity.draw = static_cast<NoiseDraw>(v); },
      [](const Plan& p) { return p.fidelity.draw == NoiseDraw::irwin_hall ? "irwin-hall" : "box-muller"; }));
  return k;
}

// The whole text as a number, or nothing.
bool parse_number(const std::string& text, double& v) {
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  return r.ec == std::errc() && r.ptr == end;
}

// Every knob's declared default set on a bare plan: the one source of the defaults.
const Plan& declared_defaults() {
  static const Plan defaults = [] {
    Plan d{.model = ModelSettings(ModelSettings::Bare{}), .fidelity = {}, .palette = {}};
    for (const Knob& k : knobs())
      if (!k.fidelity) set_knob(d, k, k.def, "the default of " + k.flag());
    return d;
  }();
  return defaults;
}

}  // namespace

ModelSettings::ModelSettings() : ModelSettings(declared_defaults().model) {}

procedural::PaletteName default_palette() { return declared_defaults().palette; }

std::string Knob::flag() const {
  std::string f = "--" + key;
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

std::string Knob::values() const {
  if (kind == KnobKind::grid)
    return "WxH, each " + format_number(min) + " .. " + format_number(max) + (unit.empty() ? "" : " " + unit) +
           (set_list ? ", or WxH,WxH,... one drawn per scenario" : "");
  if (kind == KnobKind::range)
    return (word.empty() ? std::string("X or A..B") : word + " or A..B") + ", each " + format_number(min) + " .. " +
           format_number(max) + (unit.empty() ? "" : " " + unit) +
           (drawn_ends[0] >= 0 ? ", or L1..L2/H1..H2 drawn per scenario" : "");
  if (kind == KnobKind::integer || kind == KnobKind::number)
    return format_number(min) + " .. " + format_number(max) + (unit.empty() ? "" : " " + unit) +
           (drawn >= 0 ? ", or A..B drawn per scenario" : "");
  std::string s;
  for (const std::string& c : choices) s += (s.empty() ? "" : ", ") + c;
  return s;
}

const std::vector<Knob>& knobs() {
  static const std::vector<Knob> all = declare();
  return all;
}

const Knob* find_knob(std::string_view key) {
  for (const Knob& k : knobs())
    if (k.key == key) return &k;
  return nullptr;
}

std::vector<DrawnKnob> index_draws(const std::vector<Knob>& list) {
  std::vector<DrawnKnob> by_element(PS_DRAWN_KNOBS);
  std::vector<const Knob*> claimed(PS_DRAWN_KNOBS);
  for (const Knob& k : list)
    for (const DrawnKnob& d : k.draws) {
      if (d.element >= PS_DRAWN_KNOBS)
        throw std::logic_error("knob " + k.key + ": drawn element " + std::to_string(d.element) +
                               " is not below PS_DRAWN_KNOBS (kernels/contract.h)");
      if (claimed[d.element])
        throw std::logic_error("knobs " + claimed[d.element]->key + " and " + k.key + " both claim drawn element " +
                               std::to_string(d.element));
      claimed[d.element] = &k;
      by_element[d.element] = d;
    }
  for (unsigned e = 0; e < PS_DRAWN_KNOBS; ++e)
    if (!claimed[e]) throw std::logic_error("no knob declares drawn element " + std::to_string(e));
  return by_element;
}

const std::vector<DrawnKnob>& drawn_knobs() {
  static const std::vector<DrawnKnob> d = index_draws(knobs());
  return d;
}

std::vector<std::string> drawn_number_keys() {
  std::vector<std::string> keys;
  for (const DrawnKnob& d : drawn_knobs())
    if (d.number()) keys.push_back(d.key);
  return keys;
}

PsDrawn drawn_ranges(const ModelSettings& m) {
  PsDrawn r{};
  for (const DrawnKnob& d : drawn_knobs()) {
    if (!d.number()) continue;
    const double v = std::visit(
        [&m](auto field) {
          if constexpr (std::is_same_v<decltype(field), std::monostate>)
            return 0.0;
          else
            return static_cast<double>(m.*field);
        },
        d.field);
    const DrawnRange& range = m.drawn[d.element];
    r.lo[d.element] = v;
    r.hi[d.element] = range.varies() ? range.hi : v;
  }
  return r;
}

namespace {

// One end of an integer or number knob's value, checked as the knob's own value.
double knob_number(const Knob& knob, const std::string& text, const std::string& where) {
  double v = 0;
  if (knob.kind == KnobKind::integer) {
    if (!parse_number(text, v) || v != std::floor(v) || text.find_first_of(".eE") != std::string::npos)
      throw InputError(where + ": \"" + text + "\" is not a whole number");
    if (v < knob.min || v > knob.max)
      throw InputError(where + ": " + text + " is out of range [" + knob.values() + "]");
  } else if (!parse_number(text, v) || !std::isfinite(v) || v < knob.min || v > knob.max) {
    throw InputError(where + ": \"" + text + "\" must be a finite number between " + knob.values());
  }
  return v;
}

// "L1..L2/H1..H2" of a range knob whose ends are drawn (Knob::drawn_ends), `slash` the
// position of '/': each end a number or a range within the knob's bounds, the low end's
// range wholly below the high end's, so that every scenario's range is open.
void set_drawn_ends(Plan& plan, const Knob& knob, const std::string& text, size_t slash, const std::string& where) {
  std::array<DrawnRange, 2> ends;
  for (int k = 0; k < 2; ++k) {
    const std::string part = k == 0 ? text.substr(0, slash) : text.substr(slash + 1);
    const std::string what = where + " (" + (k == 0 ? "L1..L2" : "H1..H2") + " of L1..L2/H1..H2)";
    const size_t dots = part.find("..");
    double a = 0, b = 0;
    if (dots == std::string::npos ? !parse_number(part, a)
                                  : !parse_number(part.substr(0, dots), a) || !parse_number(part.substr(dots + 2), b))
      throw InputError(what + ": \"" + part + "\" is not a number or a range A..B");
    if (dots == std::string::npos) b = a;
    if (!std::isfinite(a) || !std::isfinite(b) || a < knob.min || b > knob.max)
      throw InputError(what + ": \"" + part + "\" must be finite and within " + format_number(knob.min) + " .. " +
                       format_number(knob.max));
    if (a > b) throw InputError(what + ": \"" + part + "\" is reversed: A..B needs A <= B");
    ends[k] = {a, b};
  }
  if (ends[0].hi >= ends[1].lo)
    throw InputError(where + ": \"" + text + "\": the low end's range must lie below the high end's (L2 < H1)");
  knob.set_range(plan, ends[0].lo, ends[1].lo);
  for (int k = 0; k < 2; ++k) plan.model.drawn[static_cast<size_t>(knob.drawn_ends[k])] = ends[k];
}

// "WxH" of a grid knob, as Knob::set takes it (width * 65536 + height).
double grid_value(const Knob& knob, const std::string& text, const std::string& where) {
  const size_t x = text.find('x');
  double w = 0, h = 0;
  if (x == std::string::npos || !parse_number(text.substr(0, x), w) || !parse_number(text.substr(x + 1), h) ||
      w != std::floor(w) || h != std::floor(h) || text.find_first_of(".eE+-") != std::string::npos)
    throw InputError(where + ": \"" + text + "\" is not WxH (two whole numbers, such as 28x28)");
  if (w < knob.min || w > knob.max || h < knob.min || h > knob.max)
    throw InputError(where + ": " + text + " is out of range [" + knob.values() + "]");
  return w * 65536 + h;
}

// "WxH,WxH,..." of a grid knob drawn per scenario (Knob::set_list): at most kMaxRawGrids
// grids, none twice; the first is set as the knob's value.
void set_grid_list(Plan& plan, const Knob& knob, const std::string& text, const std::string& where) {
  std::vector<double> grids;
  size_t at = 0;
  while (true) {
    const size_t comma = text.find(',', at);
    const std::string part = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    const std::string what = where + " (grid " + std::to_string(grids.size() + 1) + " of the list)";
    if (part.empty()) throw InputError(what + ": empty; the list is WxH,WxH,... (such as 24x24,28x28)");
    const double v = grid_value(knob, part, what);
    if (std::find(grids.begin(), grids.end(), v) != grids.end())
      throw InputError(what + ": " + part + " is listed twice");
    grids.push_back(v);
    if (grids.size() > kMaxRawGrids)
      throw InputError(where + ": \"" + text + "\" lists more than " + std::to_string(kMaxRawGrids) + " grids");
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  knob.set(plan, grids[0]);
  knob.set_list(plan, grids);
}

}  // namespace

void set_knob(Plan& plan, const Knob& knob, const std::string& text, const std::string& where) {
  if (knob.drawn >= 0) {
    DrawnRange& d = plan.model.drawn[static_cast<size_t>(knob.drawn)];
    d = {};
    if (const size_t dots = text.find(".."); dots != std::string::npos) {
      const double a = knob_number(knob, text.substr(0, dots), where + " (A of A..B)");
      const double b = knob_number(knob, text.substr(dots + 2), where + " (B of A..B)");
      if (a > b) throw InputError(where + ": \"" + text + "\" is reversed: A..B needs A <= B");
      knob.set(plan, a);
      d = {a, b};
      return;
    }
  }
  double v = 0;
  switch (knob.kind) {
    case KnobKind::integer:
    case KnobKind::number:
      v = knob_number(knob, text, where);
      break;
    case KnobKind::on_off:
      if (text != "on" && text != "off") throw InputError(where + ": \"" + text + "\" is not on or off");
      v = text == "on";
      break;
    case KnobKind::grid: {
      if (knob.set_list && text.find(',') != std::string::npos) {
        set_grid_list(plan, knob, text, where);
        return;
      }
      v = grid_value(knob, text, where);
      break;
    }
    case KnobKind::range: {
      if (knob.drawn_ends[0] >= 0) {
        for (const int e : knob.drawn_ends) plan.model.drawn[static_cast<size_t>(e)] = {};
        if (const size_t slash = text.find('/'); slash != std::string::npos) {
          set_drawn_ends(plan, knob, text, slash, where);
          return;
        }
      }
      if (!knob.word.empty() && text == knob.word) {
        knob.set_range(plan, std::nan(""), std::nan(""));
        return;
      }
      const size_t dots = text.find("..");
      double a = 0, b = 0;
      const bool one = dots == std::string::npos;
      if (one ? !parse_number(text, b)
              : !parse_number(text.substr(0, dots), a) || !parse_number(text.substr(dots + 2), b))
        throw InputError(where + ": \"" + text + "\" is not " +
                         (knob.symmetric ? "a number X (for -X..X) or a range A..B" : "a range A..B (or one number)"));
      if (one) a = knob.symmetric ? 0.0 - b : b;  // 0 - 0 is +0, as an unset range's end
      if (!std::isfinite(a) || !std::isfinite(b) || a < knob.min || b > knob.max || a > b ||
          (!knob.word.empty() && a == b))
        throw InputError(where + ": \"" + text + "\" must be " + (knob.word.empty() ? "" : knob.word + " or ") +
                         "A..B with " + format_number(knob.min) +
                         (knob.word.empty() ? " <= A <= B <= " : " <= A < B <= ") + format_number(knob.max));
      knob.set_range(plan, a, b);
      return;
    }
    case KnobKind::choice: {
      size_t i = 0;
      while (i < knob.choices.size() && knob.choices[i] != text) ++i;
      if (i == knob.choices.size()) throw InputError(where + ": \"" + text + "\" is not one of " + knob.values());
      v = static_cast<double>(i);
      break;
    }
  }
  knob.set(plan, v);
}

void check_knobs(const Plan& plan) {
  for (const Knob& k : knobs()) {
    if (k.kind != KnobKind::integer && k.kind != KnobKind::number) continue;
    std::vector<double> ends;
    if (k.drawn >= 0 && plan.model.drawn[static_cast<size_t>(k.drawn)].varies()) {
      const DrawnRange& d = plan.model.drawn[static_cast<size_t>(k.drawn)];
      ends = {d.lo, d.hi};
    } else {
      ends = {k.get(plan).get<double>()};
    }
    for (const double v : ends)
      if (!std::isfinite(v) || v < k.min || v > k.max)
        throw InputError(k.flag() + ": " + format_number(v) + " must be a finite number between " + k.values());
  }
  // The thesis model composites gray levels: it has no raw grid or clothing to draw.
  if (plan.model.model == Model::thesis && plan.model.raw_grid_drawn())
    throw InputError(
        "--mmw-raw: a list of grids applies to the physics model (--model physics); the thesis model "
        "has no raw grid");
  if (plan.model.model == Model::thesis && plan.model.clothing != Clothing::catalogue)
    throw InputError(std::string("--clothing: ") + kClothingNames[static_cast<size_t>(plan.model.clothing)] +
                     " applies to the physics model (--model physics); the thesis model has the catalogue's clothing");
  // Folds belong to a drawn outfit's outer garment: the catalogue's clothing has no layers.
  if (plan.model.has_folds() && plan.model.clothing == Clothing::catalogue)
    throw InputError(
        "--clothing-folds: folds belong to an outfit's outer garment; give --clothing random (or none, shirt, "
        "sweater, jacket, coat) with --model physics");
}

std::string knob_text(const nlohmann::json& value) {
  if (value.is_boolean()) return value.get<bool>() ? "on" : "off";
  if (value.is_string()) return value.get<std::string>();
  return format_number(value.get<double>());
}

std::string knob_table_markdown() {
  Plan thesis;
  thesis.fidelity = tier_fidelity(Tier::standard);
  std::ostringstream md;
  md << "| flag | spec key | values | default | what it does |\n| --- | --- | --- | --- | --- |\n";
  for (const Knob& k : knobs())
    md << "| `" << k.flag() << "` | `" << k.key << "` | " << k.values() << " | " << knob_text(k.get(thesis))
       << (k.fidelity ? " (standard tier)" : "") << " | " << k.help << (k.fidelity ? "; overrides `--tier`" : "")
       << " |\n";
  return md.str();
}

}  // namespace portalsim
