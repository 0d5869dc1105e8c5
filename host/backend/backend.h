// The one interface both backends implement: a scene batch and a plan in, sensor
// outputs out. OpenCL (kernels/ on PoCL) and the CPU reference are interchangeable.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "plan/plan.h"
#include "scene/scene.h"

namespace portalsim {

struct BatchOutput {
  size_t n = 0;
  int mmw_width = 0, mmw_height = 0, ir_width = 0, ir_height = 0;
  std::vector<uint8_t> upper, lower;  // n * mmw_height * mmw_width, when planned
  std::vector<uint8_t> ir;            // n * ir_height * ir_width, temperature index
  std::vector<uint8_t> metal;         // n * 19
  FeatureLayout layout;
  std::vector<float> features;  // n * layout.image_features()

  const uint8_t* upper_of(size_t i) const { return upper.data() + i * mmw_width * mmw_height; }
  const uint8_t* lower_of(size_t i) const { return lower.data() + i * mmw_width * mmw_height; }
  const uint8_t* ir_of(size_t i) const { return ir.data() + i * ir_width * ir_height; }
  const uint8_t* metal_of(size_t i) const { return metal.data() + i * 19; }
  const float* features_of(size_t i) const { return features.data() + i * layout.image_features(); }
};

// Sizes `out` for n scenarios of `plan` (buffers kept for reuse): what each backend
// fills in run().
void prepare_output(BatchOutput& out, const Catalogue& cat, const Plan& plan, size_t n);

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  // Fills `out` with what `plan` asks for; `out`'s buffers are reused across calls.
  virtual void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) = 0;
};

std::unique_ptr<Backend> make_reference_backend(const Catalogue& cat, const AssetSet& assets);

}  // namespace portalsim
