#include "schedule/identity.h"

namespace portalsim {

using nlohmann::json;

std::string differing_keys(const json& was, const json& now, const std::string& prefix) {
  if (!was.is_object()) return differing_keys(json::object(), now, prefix);
  std::string out;
  const auto add = [&](const std::string& k, const json& a, const json& b) {
    if (a == b) return;
    std::string d = a.is_object() && b.is_object() && prefix.empty()
                        ? differing_keys(a, b, k + ".")
                        : prefix + k + " (" + (a.is_null() ? "absent" : a.dump()) + " there, " +
                              (b.is_null() ? "absent" : b.dump()) + " now)";
    out += (out.empty() ? "" : ", ") + d;
  };
  for (const auto& [k, v] : now.items()) add(k, was.value(k, json()), v);
  for (const auto& [k, v] : was.items())
    if (!now.contains(k)) add(k, v, json());
  return out;
}

}  // namespace portalsim
