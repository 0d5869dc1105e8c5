// Clothing drawn per scenario (`--clothing`, physics model; docs/model/clothing.md): outfits
// of layers, each a garment of a fabric. The constants are shared by the kernels' tables
// (backend/opencl/physics_params.cpp) and the CPU reference, which each compute the physics
// from them on their own.
#pragma once
#include <array>
#include <string>
#include <vector>

namespace portalsim {

// The knob's values: the catalogue's single clothing (the thesis's, every output as before),
// an outfit class drawn per scenario, or one class (its fabrics drawn per scenario).
enum class Clothing { catalogue, random, none, shirt, sweater, jacket, coat };
inline constexpr std::array<const char*, 7> kClothingNames{"catalogue", "random", "none", "shirt",
                                                           "sweater",   "jacket", "coat"};

// A fabric's power attenuation at 94 GHz per millimetre of garment (assumed within the
// bounds Bjarnason et al. 2004 measured; docs/model/clothing.md gives each value's reason).
struct Fabric {
  const char* name;
  double db_per_mm;
};
inline constexpr std::array<Fabric, 5> kFabrics{{
    {"cotton", 0.4},
    {"wool", 0.3},
    {"denim", 0.5},
    {"leather", 1.2},
    {"polyester", 0.2},
}};

// A garment: its thickness and its thermal insulation (clo; ISO 9920 / ASHRAE 55's garment
// tables), and the fabrics it is drawn in (indices into kFabrics).
struct Garment {
  const char* name;
  double thickness_mm;
  double clo;
  std::array<int, 3> fabrics;  // -1 past the last
};
inline constexpr std::array<Garment, 4> kGarments{{
    {"shirt", 0.4, 0.25, {0, 4, -1}},   // cotton, polyester
    {"sweater", 2.0, 0.36, {1, 0, 4}},  // wool, cotton, polyester
    {"jacket", 1.5, 0.44, {2, 3, 4}},   // denim, leather, polyester
    {"coat", 2.5, 0.60, {1, 3, 4}},     // wool, leather, polyester
}};

// 1 clo in m^2 K / W (ISO 9920), and the clothing surface's resistance to the room
// (convection and radiation, about 10 W/(m^2 K): the estimate ir_coupling rests on).
constexpr double kClo = 0.155;
constexpr double kSurfaceResistance = 0.1;

// One layer of an outfit, innermost first.
struct Layer {
  int garment = 0, fabric = 0;  // indices into kGarments, kFabrics
};
struct Outfit {
  std::vector<Layer> layers;
  // "none", "shirt:cotton+sweater:wool".
  std::string name() const;
  // For scenarios.csv: the layers' power transmission at 94 GHz together, and their clo.
  double transmission() const;
  double clo() const;
};

// The columns scenarios.csv adds where the clothing is drawn: each row's outfit (its name,
// transmission and clo). A scenario list's reader skips them: the seed draws them again.
inline constexpr std::array<const char*, 3> kClothingColumns{"clothing", "clothing_transmission", "clothing_clo"};

// The outfits a run draws from: classes (one for a fixed class, all five for random), each
// its outfits in order (every fabric of each layer, the outer layer's fastest). A scenario
// draws its class uniformly, then its outfit in the class uniformly (plan.h, outfit_at).
struct OutfitTable {
  std::vector<int> class_first, class_count;  // per class: its first outfit, its outfits
  std::vector<Outfit> outfits;
};
// Empty for Clothing::catalogue; made once per value.
const OutfitTable& outfit_table(Clothing c);

}  // namespace portalsim
