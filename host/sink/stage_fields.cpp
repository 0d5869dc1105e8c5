#include "sink/stage_fields.h"

#include <filesystem>
#include <fstream>

#include "backend/reference/stages.h"
#include "backend/stages.h"
#include "base/error.h"
#include "sink/tensors.h"

namespace portalsim {

void write_stage_fields(const std::string& dir, const Catalogue& cat, const AssetSet& assets, const Plan& plan,
                        const Scenario& scene, uint64_t index) {
  for (size_t v = 0; v < cat.sensors.size(); ++v) {
    const Sensor& sensor = cat.sensors[v];
    reference::ViewScene vs = reference::view_scene(cat, assets, plan.model, static_cast<int>(v), scene, index);
    vs.follow(plan);
    reference::Field field;
    const std::vector<std::string>& chain = sensor.chain_for(plan.model.model);
    for (size_t k = 0; k < chain.size(); ++k) {
      view_stage(chain[k]).reference(vs, field);
      const std::string path =
          (std::filesystem::path(dir) / (sensor.name + "." + std::to_string(k + 1) + "." + chain[k] + ".npy")).string();
      std::ofstream out(path, std::ios::binary);
      out << npy_array_header("<f8", {static_cast<uint64_t>(field.height), static_cast<uint64_t>(field.width)});
      out.write(reinterpret_cast<const char*>(field.v.data()), static_cast<std::streamsize>(field.v.size() * 8));
      if (!out.flush()) throw OutputError(path + ": cannot write");
    }
  }
}

}  // namespace portalsim
