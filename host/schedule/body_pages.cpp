#include "schedule/body_pages.h"

#include <stdexcept>

namespace portalsim {

struct BodyPages::Page {
  Catalogue cat;
  AssetSet assets;
  std::unique_ptr<Backend> backend;  // last: it holds references to the two above
};

BodyPages::BodyPages(const Catalogue& cat, const AssetSet& assets, Backend& backend, uint64_t seed)
    : cat_(cat), assets_(assets), backend_(backend), seed_(seed) {
  // The run's sinks write its catalogue's body columns: it must hold drawn bodies, page 0's.
  if (cat.subjects.size() != static_cast<size_t>(kBodyPage) || cat.subjects[0].drawn != draw_body(cat, seed, 0).drawn ||
      cat.subjects[kBodyPage - 1].drawn != draw_body(cat, seed, kBodyPage - 1).drawn)
    throw std::logic_error(
        "body pages: the run's catalogue does not hold page 0's bodies (open_catalogue with its spec)");
}

BodyPages::~BodyPages() = default;

Backend& BodyPages::backend_for(uint64_t page, SceneBatch& batch) {
  const bool borrowed = page == 0;
  if (!borrowed && (!page_ || current_ != page)) {
    page_.reset();  // the last page's images and device tables go before the next's are made
    auto p = std::make_unique<Page>();
    p->cat = cat_;
    use_page_bodies(p->cat, seed_, page);
    p->assets = with_subjects(assets_, p->cat);
    p->backend = backend_.for_catalogue(p->cat, p->assets);
    page_ = std::move(p);
    current_ = page;
  }
  const Catalogue& cat = borrowed ? cat_ : page_->cat;
  batch.bodies.resize(batch.size());
  for (size_t i = 0; i < batch.size(); ++i) {
    if (body_page(batch.index_of(i)) != page)
      throw std::logic_error("body pages: scenario " + std::to_string(batch.index_of(i)) + " is not in page " +
                             std::to_string(page));
    batch.bodies[i] = cat.subjects[batch.subject[i]].drawn;
  }
  return borrowed ? backend_ : *page_->backend;
}

}  // namespace portalsim
