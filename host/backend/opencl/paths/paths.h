// The OpenCL backend's declared paths (docs/dev/architecture.md). A view path renders one
// camera view; a features path makes the feature rows of features-only runs without
// rendering. Each fast path declares the chain of stages it implements and one gate,
// gate(plan, sensor): the one place that decides whether it runs and which of its variants
// (the kernels it launches) runs. Where no fast path's gate applies, the stage chain
// renders the view and pooling makes the features. --timing names each view's choice.
#pragma once
#include <CL/opencl.hpp>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "backend/backend.h"
#include "backend/opencl/device.h"
#include "backend/opencl/kernels.h"
#include "backend/opencl/view_launch.h"

namespace portalsim::opencl {

// A path's whole decision for one view under a plan: whether it runs, and which of its
// variants; render() and features() act on it and decide nothing more.
struct Gate {
  bool runs = false;
  int variant = 0;
  const char* variant_name = "";  // for --timing; empty where the path has one variant
};

class ViewPath {
 public:
  // chain: the stages it implements, in order (the IR path: the chain's first stages);
  // uses_field: whether its kernels pass a field of reals between them (else they write
  // the pixels).
  ViewPath(const char* name, std::vector<std::string> chain, bool uses_field)
      : name_(name), chain_(std::move(chain)), uses_field_(uses_field) {}
  virtual ~ViewPath() = default;
  const char* name() const { return name_; }
  const std::vector<std::string>& chain() const { return chain_; }
  bool uses_field() const { return uses_field_; }
  virtual Gate gate(const Plan& plan, const Sensor& sensor) const = 0;
  bool applies(const Plan& plan, const Sensor& sensor) const { return gate(plan, sensor).runs; }
  // Renders the view as its gate decided, after place_view has written its records.
  virtual void render(ViewLaunch& v, const Gate& g) const = 0;

 private:
  const char* name_;
  std::vector<std::string> chain_;
  bool uses_field_;
};

// A view's path and its gate's decision.
struct ViewRoute {
  const ViewPath* path = nullptr;
  Gate gate;
};

// The view paths in the order they are tried; the last, the stage chain, applies to all.
const std::vector<const ViewPath*>& view_paths();
// The first view path whose gate applies, and its decision.
ViewRoute view_route(const Plan& plan, const Sensor& sensor);
inline const ViewPath& view_path(const Plan& plan, const Sensor& sensor) { return *view_route(plan, sensor).path; }
// "physics_raw (fixed window)": a path's name and its variant's, as --timing shows them.
std::string describe(const char* path, const Gate& g);

// The view paths, one line each, in the order they are tried: the fast paths, then the
// stage chain, which applies to every view. NAME is paths/NAME.cpp, defining NAME_path().
#define PORTALSIM_VIEW_PATHS(X) \
  X(thesis_images)              \
  X(physics_raw)                \
  X(ir_fused)                   \
  X(stage_chain)
#define PORTALSIM_DECLARE_VIEW_PATH(name) const ViewPath& name##_path();
PORTALSIM_VIEW_PATHS(PORTALSIM_DECLARE_VIEW_PATH)
#undef PORTALSIM_DECLARE_VIEW_PATH

// The stage chain from its stage `from` on, each stage's kernels in order.
void run_stages(ViewLaunch& v, size_t from);
// The physics MMW raw grid alone (physics_raw's first kernel), into Device::raw.
void run_raw_grid(ViewLaunch& v);

class FeaturePath {
 public:
  virtual ~FeaturePath() = default;
  virtual const char* name() const = 0;
  // Whether it makes `plan`'s features of the pooled view `sensor`, and how; the path runs
  // where its gate applies to every pooled view.
  virtual Gate gate(const Plan& plan, const Sensor& sensor) const = 0;
  bool applies(const Plan& plan, const Sensor& sensor) const { return gate(plan, sensor).runs; }
  // Writes the batch's image features (blocks and regions) into `features`, as `g` decided.
  virtual void features(Kernels& K, const Plan& plan, const Gate& g, const DeviceBatch& b, cl::Buffer& features) = 0;
};

// The features paths, one line each, in the order they are tried (where none applies, the
// rendered pooled views are pooled). NAME is paths/NAME.cpp, defining NAME_path(Device&).
#define PORTALSIM_FEATURE_PATHS(X) \
  X(thesis_sparse_features)        \
  X(physics_raw_features)
#define PORTALSIM_DECLARE_FEATURE_PATH(name) std::unique_ptr<FeaturePath> name##_path(Device& d);
PORTALSIM_FEATURE_PATHS(PORTALSIM_DECLARE_FEATURE_PATH)
#undef PORTALSIM_DECLARE_FEATURE_PATH

// Block and region means of one rendered pooled view (slot of `lay`) into its columns of
// the feature rows: the features of every plan no features path takes.
void pool_view(Device& d, Kernels& K, const FeatureLayout& lay, const DeviceBatch& b, int slot, const cl::Buffer& img,
               const cl::Buffer& features);
// The block-mean noise model: each mean gets N(0, sigma^2 / pixels) from the generator.
void block_mean_noise(Device& d, Kernels& K, const Plan& plan, const DeviceBatch& b, const cl::Buffer& features);

// The metal detector's zones, thesis or physics model, into out.metal.
class MetalPath {
 public:
  explicit MetalPath(Device& d);
  void run(Kernels& K, const Plan& plan, const DeviceBatch& b, BatchOutput& out);

 private:
  Device& d_;
  cl::Buffer zone_rec_, region_rec_, tensors_;  // the coil model's tables
  Grown out_;
};

}  // namespace portalsim::opencl
