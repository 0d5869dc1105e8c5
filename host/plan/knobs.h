// Every knob of the sensor model and of the fidelity tiers, declared once: its key, the
// values it takes, its default and its help. The command-line flags, the spec-file keys,
// the checks, the manifest entries and the knob table of docs/reference/knobs.md all come from this list.
#pragma once
#include <array>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "plan/plan.h"

namespace portalsim {

enum class KnobKind { integer, number, on_off, choice, grid, range };

// A value drawn per scenario from its element of PS_STREAM_KNOB_DRAW (docs/model/drawn-knobs.md),
// declared with its knob (knobs.cpp: drawable, drawable_ends, drawn_by): the declarations are
// the one list of elements, keys, columns and draws.
struct DrawnKnob {
  unsigned element = 0;  // its PS_DRAWN_* (the Philox counter's element: bytes depend on it)
  std::string key{};     // a number's column: scenarios.csv's <key>, data.h5's param_<key>
  // The field a number's draw sets (at_scenario, drawn_knob_at): a real one lo + (hi - lo)
  // uniform24(word 0), a whole one lo + below(word 0, hi - lo + 1). None for a draw of its own
  // (the outfit: outfit_at; the raw grid: raw_grid_at).
  std::variant<std::monostate, double ModelSettings::*, int ModelSettings::*> field{};
  bool number() const { return field.index() != 0; }
};

// Filled by field name (designated initializers): each field left out takes its default.
struct Knob {
  std::string key{};  // spec-file key and manifest entry; the flag is "--" + key with '-' for '_'
  // The default as set_knob reads it ("3", "28x28", "290..302", "thesis"): the one place it
  // is written (a ModelSettings made with no arguments holds the knobs' defaults). Empty for
  // a fidelity knob, whose default is the tier's.
  std::string def{};
  KnobKind kind{};
  double min = 0, max = 0;             // integer and number; each side of a grid; each end of a range
  std::vector<std::string> choices{};  // choice
  std::string unit{};                  // integer and number, for the help and the README
  std::string help{};
  bool fidelity = false;  // overrides the tier (its default comes from the tier)
  bool identity = true;   // part of a data set's identity (checked on --resume)
  // Left out of a manifest's spec at its default: a knob added after data sets were made,
  // which keep their identity (and bytes) where it is not used.
  bool omit_default = false;
  // Sets the knob from a checked value: the number, 0/1 for on_off, the choice's index, or
  // width * 65536 + height for a grid ("WxH").
  std::function<void(Plan&, double)> set{};
  // The knob's value in `plan`: a number, a bool (on_off) or the choice's name.
  std::function<nlohmann::json(const Plan&)> get{};
  // A range ("A..B", A <= B) is set by set_range instead of set; one number X means X..X,
  // or -X..X for a symmetric range (get then gives the short form back where it applies).
  bool symmetric = false;
  std::function<void(Plan&, double, double)> set_range{};
  // A range that also takes this one word ("auto"), set as set_range(NaN, NaN); its A..B
  // must then have A < B.
  std::string word{};
  // An integer or number knob that may be drawn per scenario: its PS_DRAWN_* element, or -1.
  // "A..B" (A <= B, each within its range) then sets ModelSettings::drawn and the field to A;
  // get gives "A..B" back where A < B.
  int drawn = -1;
  // A range knob whose ends may each be drawn per scenario (the window): the PS_DRAWN_*
  // elements of its A and B ends, or -1. "L1..L2/H1..H2" (each end a number or a range,
  // L2 < H1) sets ModelSettings::drawn and the range to L1..H1; get gives it back so.
  std::array<int, 2> drawn_ends{-1, -1};
  // A grid knob that may be drawn per scenario from a list ("WxH,WxH,..."): sets the list,
  // each grid as set takes it, after set has set the first; null where the grid is one.
  std::function<void(Plan&, const std::vector<double>&)> set_list{};
  // What the knob draws per scenario (one number, each end of the window, the outfit or the
  // raw grid); empty where nothing is drawn.
  std::vector<DrawnKnob> draws{};

  std::string flag() const;
  // "0 .. 1000 gray levels", "on, off", "fp32, fp64, fixed16", "X or A..B, each 0.1 .. 10".
  std::string values() const;
};

const std::vector<Knob>& knobs();
// The draws of knobs(), by element: entry e is PS_DRAWN_KNOBS's element e.
const std::vector<DrawnKnob>& drawn_knobs();
// The drawn numbers' keys: the columns that record a run's draws (scenarios.csv), which a
// scenario list skips (ScenarioRows: the seed draws them again).
std::vector<std::string> drawn_number_keys();
// Each drawn number's range in `m`, by element, as the kernels draw it (kernels/contract.h,
// PsDrawn): lo the field's value, hi the drawn range's upper end or that value where fixed.
PsDrawn drawn_ranges(const ModelSettings& m);
// The draws of `list`, by element; throws std::logic_error where two claim one element or an
// element below PS_DRAWN_KNOBS has none (drawn_knobs checks knobs() so).
std::vector<DrawnKnob> index_draws(const std::vector<Knob>& list);
// Null when no knob has this key.
const Knob* find_knob(std::string_view key);

// Checks `text` against the knob ("2.5", "on", "bilinear"), then sets it in `plan`;
// throws InputError starting with `where` (a flag or "file:line: key").
void set_knob(Plan& plan, const Knob& knob, const std::string& text, const std::string& where);
// Throws InputError naming the knob's flag when a value in `plan` is outside its range.
void check_knobs(const Plan& plan);
// The value as set_knob reads it back: "10", "2.5", "on", "bilinear".
std::string knob_text(const nlohmann::json& value);

// The knob table of docs/reference/knobs.md (Markdown), from the declarations.
std::string knob_table_markdown();

}  // namespace portalsim
