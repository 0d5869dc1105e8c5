#include "backend/backend.h"

#include <algorithm>
#include <stdexcept>

#include "base/parallel.h"

namespace portalsim {

void prepare_output(BatchOutput& out, const Catalogue& cat, const Plan& plan, size_t n) {
  out.n = n;
  out.views.resize(cat.sensors.size());
  for (size_t k = 0; k < cat.sensors.size(); ++k) {
    const Sensor& s = cat.sensors[k];
    ViewImages& v = out.views[k];
    v.name = s.name;
    v.camera = s.camera;
    v.palette = s.palette;
    v.width = s.width;
    v.height = s.height;
    v.pixels.resize(plan.image(static_cast<int>(k)) ? n * s.pixels() : 0);
  }
  out.layout = FeatureLayout::of(cat, plan.model.block);
  out.metal.resize(plan.metal ? n * cat.zones : 0);
  out.features.resize(plan.features ? n * out.layout.image_features() : 0);
}

void Backend::annotations(const Catalogue& cat, const AssetSet& assets, const SceneBatch& batch, const Plan& plan,
                          BatchOutput& out) {
  if (plan.annotations) {
    if (!annotator_) annotator_ = std::make_unique<Annotator>(cat, assets);
    (*annotator_)(plan.model, batch, out.annotations, default_threads());
  } else
    out.annotations.clear();
}

const ViewImages& BatchOutput::view(std::string_view name) const {
  for (const ViewImages& v : views)
    if (v.name == name) return v;
  throw std::out_of_range("no camera view is called \"" + std::string(name) + "\"");
}

void place_rows(BatchOutput& all, const BatchOutput& part, const std::vector<size_t>& rows) {
  if (rows.size() != part.n) throw std::logic_error("place_rows: the rows are not the part's scenarios");
  // Row j of `from` (`per` values a scenario) to row rows[j] of `to`; empty where not asked for.
  const auto place = [&rows](auto& to, const auto& from, size_t per, size_t j) {
    if (!from.empty()) std::copy_n(from.begin() + j * per, per, to.begin() + rows[j] * per);
  };
  // A part's images are most of its bytes (about 100 kB a scenario in the built-in portal):
  // copied on every core, as the kernels made them.
  parallel_for(rows.size(), default_threads(), [&](size_t lo, size_t hi) {
    for (size_t j = lo; j < hi; ++j) {
      for (size_t k = 0; k < part.views.size(); ++k)
        place(all.views[k].pixels, part.views[k].pixels, part.views[k].pixels_per_image(), j);
      place(all.metal, part.metal, static_cast<size_t>(part.layout.zones), j);
      place(all.features, part.features, static_cast<size_t>(part.layout.image_features()), j);
    }
  });
}

void append_output(BatchOutput& all, const BatchOutput& part) {
  all.n += part.n;
  all.layout = part.layout;
  all.views.resize(part.views.size());
  for (size_t k = 0; k < part.views.size(); ++k) {
    std::vector<uint8_t> pixels = std::move(all.views[k].pixels);
    all.views[k] = part.views[k];
    pixels.insert(pixels.end(), part.views[k].pixels.begin(), part.views[k].pixels.end());
    all.views[k].pixels = std::move(pixels);
  }
  all.metal.insert(all.metal.end(), part.metal.begin(), part.metal.end());
  all.features.insert(all.features.end(), part.features.begin(), part.features.end());
  all.annotations.resize(part.annotations.size());
  for (size_t k = 0; k < part.annotations.size(); ++k) {
    ViewAnnotations& a = all.annotations[k];
    const ViewAnnotations& p = part.annotations[k];
    const uint32_t scenarios = a.first.empty() ? 0 : static_cast<uint32_t>(a.first.size() - 1);
    const uint32_t items = static_cast<uint32_t>(a.items.size());
    a.width = p.width;
    a.height = p.height;
    a.masks.insert(a.masks.end(), p.masks.begin(), p.masks.end());
    if (!a.first.empty()) a.first.pop_back();
    for (uint32_t f : p.first) a.first.push_back(f + items);
    for (Annotation x : p.items) {
      x.scenario += scenarios;
      a.items.push_back(x);
    }
  }
}

}  // namespace portalsim
