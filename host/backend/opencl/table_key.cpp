#include "backend/opencl/table_key.h"

#include "plan/knobs.h"

namespace portalsim::opencl {

std::string table_key(const Plan& plan, const std::string& extra) {
  std::string key;
  for (const Knob& k : knobs()) key += k.key + "=" + k.get(plan).dump() + ";";
  return key + extra;
}

}  // namespace portalsim::opencl
