#include "schedule/identity.h"

namespace portalsim {

using nlohmann::json;

namespace {

// A value as a message shows it: text without JSON's quotes (but "" for empty text),
// "absent" for a missing entry.
std::string shown(const json& v) {
  if (v.is_null()) return "absent";
  if (v.is_string()) return v.get<std::string>().empty() ? "\"\"" : v.get<std::string>();
  return v.dump();
}

}  // namespace

std::string differing_keys(const json& was, const json& now, const Sides& sides, const std::string& prefix) {
  if (!was.is_object()) return differing_keys(json::object(), now, sides, prefix);
  std::string out;
  const auto add = [&](const std::string& k, const json& a, const json& b) {
    if (a == b) return;
    std::string d = a.is_object() && b.is_object() && prefix.empty()
                        ? differing_keys(a, b, sides, k + ".")
                        : prefix + k + ": " + shown(a) + " " + sides.was + ", " + shown(b) + " " + sides.now;
    out += (out.empty() ? "" : "; ") + d;
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
