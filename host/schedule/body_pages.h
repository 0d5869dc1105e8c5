// Per-scenario bodies (--bodies per-scenario, scene/bodies.h): a run takes its scenarios a
// page of bodies at a time. Each page has its own catalogue (the run's, with the page's
// bodies as its subjects), images and backend, made when a batch first needs the page.
#pragma once
#include <memory>

#include "assets/assets.h"
#include "backend/backend.h"
#include "scene/bodies.h"
#include "scene/catalogue.h"

namespace portalsim {

class BodyPages {
 public:
  // `cat`, `assets` and `backend` are the run's, and page 0's: `cat`'s subjects must be page
  // 0's bodies of `seed` (open_catalogue makes them so; else std::logic_error).
  BodyPages(const Catalogue& cat, const AssetSet& assets, Backend& backend, uint64_t seed);
  ~BodyPages();
  // The backend for page `page`'s scenarios, and their bodies' records in `batch.bodies`
  // (all of the batch's scenarios must lie in the page).
  Backend& backend_for(uint64_t page, SceneBatch& batch);

 private:
  struct Page;
  const Catalogue& cat_;
  const AssetSet& assets_;
  Backend& backend_;
  uint64_t seed_;
  std::unique_ptr<Page> page_;  // the page made last (null while page 0 runs on the run's)
  uint64_t current_ = 0;
};

}  // namespace portalsim
