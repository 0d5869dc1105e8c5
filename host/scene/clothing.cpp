#include "scene/clothing.h"

#include <cmath>

#include "base/plain_math.h"

namespace portalsim {

std::string Outfit::name() const {
  if (layers.empty()) return "none";
  std::string s;
  for (const Layer& l : layers) {
    if (!s.empty()) s += '+';
    s += std::string(kGarments[l.garment].name) + ":" + kFabrics[l.fabric].name;
  }
  return s;
}

double Outfit::transmission() const {
  double db = 0;
  for (const Layer& l : layers) db += kFabrics[l.fabric].db_per_mm * kGarments[l.garment].thickness_mm;
  return plain::exp10(-db / 10.0);
}

double Outfit::clo() const {
  double c = 0;
  for (const Layer& l : layers) c += kGarments[l.garment].clo;
  return c;
}

namespace {

// The garments of each class, innermost first: a shirt under a sweater, a jacket or a coat
// (and a sweater under the coat).
std::vector<int> class_garments(Clothing c) {
  switch (c) {
    case Clothing::shirt:
      return {0};
    case Clothing::sweater:
      return {0, 1};
    case Clothing::jacket:
      return {0, 2};
    case Clothing::coat:
      return {0, 1, 3};
    default:
      return {};
  }
}

// Every outfit of the garments, each layer in each of its fabrics.
void add_outfits(const std::vector<int>& garments, OutfitTable& t) {
  t.class_first.push_back(static_cast<int>(t.outfits.size()));
  std::vector<Outfit> made{Outfit{}};
  for (int g : garments) {
    std::vector<Outfit> next;
    for (const Outfit& o : made)
      for (int f : kGarments[g].fabrics) {
        if (f < 0) continue;
        Outfit n = o;
        n.layers.push_back({g, f});
        next.push_back(n);
      }
    made = std::move(next);
  }
  t.outfits.insert(t.outfits.end(), made.begin(), made.end());
  t.class_count.push_back(static_cast<int>(made.size()));
}

OutfitTable make_outfit_table(Clothing c) {
  OutfitTable t;
  if (c == Clothing::catalogue) return t;
  if (c == Clothing::random) {
    for (Clothing k : {Clothing::none, Clothing::shirt, Clothing::sweater, Clothing::jacket, Clothing::coat})
      add_outfits(class_garments(k), t);
  } else {
    add_outfits(class_garments(c), t);
  }
  return t;
}

}  // namespace

const OutfitTable& outfit_table(Clothing c) {
  static const std::array<OutfitTable, kClothingNames.size()> tables = [] {
    std::array<OutfitTable, kClothingNames.size()> t;
    for (size_t k = 0; k < t.size(); ++k) t[k] = make_outfit_table(static_cast<Clothing>(k));
    return t;
  }();
  return tables.at(static_cast<size_t>(c));
}

}  // namespace portalsim
