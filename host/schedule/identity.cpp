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

json run_manifest(const json& identity, uint64_t count, uint64_t positive, uint64_t negative,
                  const std::vector<FileState>& outputs, bool image_folders) {
  json manifest = identity;
  manifest["count"] = count;
  manifest["classes"] = {{"positive", positive}, {"negative", negative}};
  manifest["outputs"] = json::array();
  for (const FileState& f : outputs)
    manifest["outputs"].push_back({{"name", f.name}, {"bytes", f.bytes}, {"xxh3_64", xxh3_hex(f.xxh3)}});
  if (image_folders) manifest["images"] = {{"folder", "images"}, {"count", count}};
  return manifest;
}

}  // namespace portalsim
