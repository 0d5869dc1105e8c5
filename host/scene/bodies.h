// Random bodies (`--bodies random`): a run's subjects drawn from anthropometric
// distributions instead of the catalogue's named ones (docs/model/bodies.md).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/catalogue.h"

namespace portalsim {

// The most bodies a run may draw: scenarios name their subject in a byte.
constexpr int kMaxRandomBodies = 255;
constexpr int kDefaultRandomBodies = 64;

// What one drawn body was drawn as, in the survey's units, for bodies.csv.
struct DrawnBody {
  bool female = false;
  double stature_mm = 0, shoulders_mm = 0, chest_mm = 0, hips_mm = 0;  // biacromial, chest, hip breadth
  double crotch_ratio = 0, arm_ratio = 0;                              // crotch height and arm length over stature
};

// The columns scenarios.csv adds for a run of random bodies: each row's body as drawn
// (Subject::drawn). A scenario list's reader skips them: the seed draws the bodies again.
inline constexpr std::array<const char*, 11> kBodyColumns{
    "sex",       "stature_mm", "shoulders_mm",    "chest_mm",         "hips_mm", "crotch_ratio",
    "arm_ratio", "pose",       "skin_emissivity", "skin_temperature", "texture"};

// Whether the catalogue's subjects are drawn bodies (use_random_bodies).
inline bool drawn_bodies(const Catalogue& cat) { return !cat.subjects.empty() && !cat.subjects[0].drawn.empty(); }

// A drawn body in a few words ("female, 1.62 m, arms-raised"); empty for the catalogue's.
std::string body_summary(const Subject& s);

// Body k (0-based) of a run: a pure function of (seed, k) on the counter generator's
// PS_STREAM_BODIES stream, whatever the run's count, batch or shard. `cat` gives the
// skin's defaults and the IR index map the subject's images are drawn in.
Subject draw_body(const Catalogue& cat, uint64_t seed, uint64_t k, DrawnBody* drawn = nullptr);

// Replaces the catalogue's subjects by `count` drawn bodies ("body-001", ...) and derives
// every view's places on them again.
void use_random_bodies(Catalogue& cat, uint64_t seed, int count);

// Per-scenario bodies (--bodies per-scenario): scenario i carries body i, drawn as above.
// The kernels name a scenario's subject in a byte, so a run takes its scenarios a page at
// a time: page p's catalogue holds the bodies of scenarios [p kBodyPage, (p + 1) kBodyPage)
// and scenario i is its subject i mod kBodyPage. A multiple of data.h5's chunk rows, so
// that a page's batch ends where a chunk does.
constexpr int kBodyPage = 192;
inline uint64_t body_page(uint64_t index) { return index / kBodyPage; }
inline int page_subject(uint64_t index) { return static_cast<int>(index % kBodyPage); }
// Replaces the catalogue's subjects by page `page`'s bodies and derives every view's places
// on them again.
void use_page_bodies(Catalogue& cat, uint64_t seed, uint64_t page);

}  // namespace portalsim
