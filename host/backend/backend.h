// The one interface both backends implement: a scene batch and a plan in, sensor
// outputs out. OpenCL (kernels/ on PoCL) and the CPU reference are interchangeable.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "assets/assets.h"
#include "backend/annotate.h"
#include "plan/plan.h"
#include "scene/scene.h"

namespace portalsim {

// One camera view's images for a batch: n images of height x width, 8-bit (MMW gray,
// IR temperature index); empty when the plan does not keep this view.
struct ViewImages {
  std::string name;
  Camera camera = Camera::mmw;
  bool palette = false;  // temperature indices, written through the palette
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
  size_t pixels_per_image() const { return static_cast<size_t>(width) * height; }
  const uint8_t* of(size_t i) const { return pixels.data() + i * pixels_per_image(); }
  bool empty() const { return pixels.empty(); }
};

struct BatchOutput {
  size_t n = 0;
  std::vector<ViewImages> views;  // one per camera view, in Catalogue::sensors order
  std::vector<uint8_t> metal;     // n * layout.zones
  FeatureLayout layout;
  std::vector<float> features;  // n * layout.image_features()
  // Per camera view, boxes and instance masks (backend/annotate.h); empty unless the plan
  // asks for annotations.
  std::vector<ViewAnnotations> annotations;

  // The view called `name` (a Catalogue::sensors name); throws std::out_of_range if none is.
  const ViewImages& view(std::string_view name) const;
  const uint8_t* metal_of(size_t i) const { return metal.data() + i * layout.zones; }
  const float* features_of(size_t i) const { return features.data() + i * layout.image_features(); }
};

// Sizes `out` for n scenarios of `plan` (buffers kept for reuse): what each backend
// fills in run().
void prepare_output(BatchOutput& out, const Catalogue& cat, const Plan& plan, size_t n);

// Appends `part`'s scenarios to `all` (same catalogue and plan).
void append_output(BatchOutput& all, const BatchOutput& part);
// Puts `part`'s scenario j at row rows[j] of `all` (sized for the whole batch, the same
// layout): its images, metal zones and features; annotations are left to the caller.
void place_rows(BatchOutput& all, const BatchOutput& part, const std::vector<size_t>& rows);

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  // Fills `out` with what `plan` asks for; `out`'s buffers are reused across calls.
  virtual void run(const SceneBatch& batch, const Plan& plan, BatchOutput& out) = 0;
  // How run() makes `plan`'s outputs, as --timing names it: per rendered view and for the
  // features, the path taken ("upper: physics_raw (fixed window)").
  virtual std::vector<std::string> paths(const Plan& plan) const = 0;
  // The camera views run() renders for `plan` (indices into Catalogue::sensors): those whose
  // images are kept, and the pooled ones where no features path makes the features.
  virtual std::vector<int> rendered_views(const Plan& plan) const = 0;
  // The same backend (its device and settings) for another catalogue's subjects: a page of
  // per-scenario bodies (scene/bodies.h). `cat` and `assets` must outlive it.
  virtual std::unique_ptr<Backend> for_catalogue(const Catalogue& cat, const AssetSet& assets) const = 0;
  // paths()'s name for features made by pooling the rendered views, the way both backends can.
  static constexpr const char* kPooledFeatures = "pooled from the rendered views";

 protected:
  // The annotations `plan` asks for (the same function for every backend), or none.
  // `cat` and `assets` are the backend's own, the same in every call.
  void annotations(const Catalogue& cat, const AssetSet& assets, const SceneBatch& batch, const Plan& plan,
                   BatchOutput& out);

 private:
  std::unique_ptr<Annotator> annotator_;  // made on the first batch with annotations
};

std::unique_ptr<Backend> make_reference_backend(const Catalogue& cat, const AssetSet& assets);

}  // namespace portalsim
