// The paths of the speed table (issue 14's, and physics images and annotations): what
// each computes in kernel, in its plain loop (bench/baseline/) and in the fp64
// reference, and what `generate` runs for it end to end. `portalsim bench` and
// portalsim_bench (bench/*.cpp) both time these.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/backend.h"
#include "schedule/run_spec.h"

namespace portalsim::speed {

struct SpeedPath {
  std::string key;    // "noisy_images": the JSON's and --paths's name
  std::string title;  // what the table's row says
  RunSpec spec;       // what generate runs end to end (the caller sets count)
  Plan kernel;        // what the kernels, the loop and the reference compute per batch
  bool has_loop = true;
  bool needs_fp64_end_to_end = false;  // generate computes metal zones, in fp64 under physics
};

// features, images, noisy_images, physics_images, annotations, in that order.
std::vector<SpeedPath> speed_paths();
// The paths `keys` names (--paths's keys; empty: all), in speed_paths()'s order: what
// `portalsim bench` measures and its notes speak of. Throws InputError naming an unknown key.
std::vector<SpeedPath> chosen_paths(const std::vector<std::string>& keys);
// The features-only plan of issue 14 (thesis, sparse pooling, block 10, no metal).
Plan features_plan();
// Every camera view's images, no features or metal, per-pixel noise sigma `sigma`.
Plan images_plan(double sigma);

// n scenarios of the generator (seed 1), 0 to max_objects objects each.
SceneBatch make_batch(const Catalogue& cat, size_t n, int max_objects = 4);

// Output bytes per scenario that the device writes into `out` (views, metal, features):
// not the annotations' masks, which the host paints only where objects lie.
double output_bytes_per_scenario(const BatchOutput& out);

// A path's plain loop (bench/baseline/), tables made once; for annotations, the image
// loop and the host annotator that both backends use.
class Loop {
 public:
  Loop(const Catalogue& cat, const AssetSet& assets, const SpeedPath& path);
  ~Loop();
  // `out` sized by prepare_output for path.kernel.
  void run(const SceneBatch& batch, BatchOutput& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace portalsim::speed
