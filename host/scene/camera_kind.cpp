#include "scene/camera_kind.h"

#include <stdexcept>

namespace portalsim {

// The kinds, one X(NAME) each, in the order of Camera: NAME is camera_NAME.cpp, which
// defines NAME_camera(), the kind's declaration.
#define PORTALSIM_CAMERA_KINDS(X) X(mmw) X(ir)

#define PORTALSIM_DECLARE_CAMERA_KIND(name) const CameraKind& name##_camera();
PORTALSIM_CAMERA_KINDS(PORTALSIM_DECLARE_CAMERA_KIND)
#undef PORTALSIM_DECLARE_CAMERA_KIND

const std::vector<const CameraKind*>& camera_kinds() {
#define PORTALSIM_CAMERA_KIND_ADDRESS(name) &name##_camera(),
  static const std::vector<const CameraKind*> kinds = {PORTALSIM_CAMERA_KINDS(PORTALSIM_CAMERA_KIND_ADDRESS)};
#undef PORTALSIM_CAMERA_KIND_ADDRESS
  return kinds;
}

const CameraKind& camera_kind(Camera c) {
  const auto k = static_cast<size_t>(c);
  if (k >= camera_kinds().size() || camera_kinds()[k]->camera != c)
    throw std::logic_error("camera kind " + std::to_string(k) + " is not in the registry at its index");
  return *camera_kinds()[k];
}

const CameraKind* camera_kind_named(std::string_view name) {
  for (const CameraKind* k : camera_kinds())
    if (name == k->name) return k;
  return nullptr;
}

std::string camera_kind_names() {
  std::string s;
  const std::vector<const CameraKind*>& kinds = camera_kinds();
  for (size_t k = 0; k < kinds.size(); ++k)
    s += (k == 0 ? "" : k + 1 == kinds.size() ? " or " : ", ") + std::string("\"") + kinds[k]->name + "\"";
  return s;
}

}  // namespace portalsim
