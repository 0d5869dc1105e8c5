// Everything one camera view's kernels read under a plan, derived in one step and kept in
// one cache bounded in size, keyed by the knob registry (table_key.h), as darktable's
// commit_params derives a module's data from its parameters: the view's knobs (its own
// camera's numbers over the run's), its launch settings (PsViewLaunch), the physics
// parameters and tables, and the features paths' own tables. A knob reaches a kernel by
// this route alone; ViewLaunch adds the batch's fields.
#pragma once
#include <CL/opencl.hpp>
#include <memory>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/opencl/launch.h"
#include "base/lru_cache.h"
#include "plan/plan.h"
#include "scene/catalogue.h"

namespace portalsim::opencl {

// A features path's tables for a view (paths/*_features.cpp): made by the path on first
// use, as they need its kernels run, and kept with the view's derivation.
// Tables per object drawing are made for the drawings the run's batches carry, not the
// catalogue's every one (a run draws from its pool: 14 of the 42 drawings by default), and
// made again with the union when a batch brings another; a drawing's entries are the same
// whichever others are tabulated.
struct PathTables {
  virtual ~PathTables() = default;
  std::vector<char> variants;  // by variant id: tabulated
  bool covers(const std::vector<char>& batch) const {
    for (size_t v = 0; v < batch.size(); ++v)
      if (batch[v] && (v >= variants.size() || !variants[v])) return false;
    return true;
  }
};
// What tables for `batch` cover: the kept tables' drawings and the batch's.
inline std::vector<char> tabulated_variants(const PathTables* kept, const std::vector<char>& batch) {
  std::vector<char> v = batch;
  if (kept)
    for (size_t k = 0; k < v.size() && k < kept->variants.size(); ++k) v[k] = v[k] || kept->variants[k];
  return v;
}

struct ViewDerived {
  ModelSettings model;  // the plan's knobs as this view takes them (ModelSettings::for_view)
  // Every field but the batch's (n, seed, first) and the features path's PS_FLAG_TABULATED.
  PsViewLaunch L{};
  cl::Buffer phys;            // the kind's scalars, tails and the tables L.tables places (a placeholder: thesis)
  size_t raw_values = 1;      // the MMW raw grid's values per scenario (physics)
  size_t scratch_values = 1;  // the view's scratch values per scenario (physics)
  std::unique_ptr<PathTables> path_tables;
};

class ViewDerivations {
 public:
  ViewDerivations(const Catalogue& cat, const AssetSet& assets, cl::Context& ctx);
  // View `view`'s derivation under `plan`, made on first use; noise_free: the MMW raw grid
  // without its NETD (the physics features path draws it per feature). The pointer keeps
  // it whole while in use, even where the cache drops it meanwhile.
  std::shared_ptr<ViewDerived> operator()(const Plan& plan, int view, bool noise_free = false);
  size_t size() const { return cache_.size(); }
  size_t capacity() const { return cache_.capacity(); }
  // Room for `parts` plans' derivations used by turns in every batch (a raw grid drawn
  // from a list of that many: each grid's part has its own), so that none is dropped and
  // made again batch after batch.
  void hold_parts(size_t parts) { cache_.reserve(per_plan_ * std::max<size_t>(parts, 1)); }
  // What a derivation depends on: every knob, the view, and the parts of the plan
  // outside the registry that the launch settings read.
  static std::string key(const Plan& plan, int view, bool noise_free);

 private:
  const Catalogue& cat_;
  const AssetSet& assets_;
  cl::Context& ctx_;
  size_t per_plan_;  // room for one plan's derivations, and some: the cache's least capacity
  LruCache<std::string, std::shared_ptr<ViewDerived>> cache_;
};

}  // namespace portalsim::opencl
