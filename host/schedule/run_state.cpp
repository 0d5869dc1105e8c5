#include "schedule/run_state.h"

#include "base/error.h"

namespace portalsim {

using nlohmann::json;

namespace {

// Parsed, or `Error` naming `path` and what JSON said.
template <class Error>
json parse(std::string_view text, const std::string& path, const std::string& what) {
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw Error(path + ": " + what + ": " + e.what());
  }
}

const json& field(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + key + ": missing");
  return j[key];
}

uint64_t count_field(const json& j, const char* key, const std::string& where) {
  const json& v = field(j, key, where);
  if (!v.is_number_unsigned()) throw InputError(where + key + ": not a count");
  return v.get<uint64_t>();
}

// Every field a join reads, checked before it is trusted: counts are counts, output
// names are plain file names (no folder, nothing hidden), hashes are 16 hex digits.
void check_manifest(const json& m) {
  if (!m.is_object()) throw InputError("expected a JSON object");
  const uint64_t begin = count_field(field(m, "shard", ""), "begin", "shard."),
                 end = count_field(m["shard"], "end", "shard."), count = count_field(m, "count", "");
  if (end < begin || count != end - begin) throw InputError("shard: its range and count disagree");
  const json& spec = field(m, "spec", "");
  if (end > manifest_total(spec)) throw InputError("shard.end: past the spec's count");
  const json& classes = field(m, "classes", "");
  if (count_field(classes, "positive", "classes.") + count_field(classes, "negative", "classes.") != count)
    throw InputError("classes: do not add up to count");
  const json& outputs = field(m, "outputs", "");
  if (!outputs.is_array() || outputs.size() > 64) throw InputError("outputs: not a list of outputs");
  for (const json& o : outputs) {
    const json& name = field(o, "name", "outputs[].");
    if (!name.is_string()) throw InputError("outputs[].name: not a string");
    const std::string n = name.get<std::string>();
    if (n.empty() || n.size() > 255 || n[0] == '.' ||
        n.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") != std::string::npos)
      throw InputError("outputs[].name: \"" + n + "\" is not a plain file name");
    count_field(o, "bytes", "outputs[].");
    const json& h = field(o, "xxh3_64", "outputs[].");
    if (!h.is_string() || h.get<std::string>().size() != 16 ||
        h.get<std::string>().find_first_not_of("0123456789abcdef") != std::string::npos)
      throw InputError("outputs[].xxh3_64: not 16 hexadecimal digits");
  }
}

// A checkpoint's fields have the types the resume reads.
void check_checkpoint(const json& c, const std::string& path) {
  const auto whole = [&](const json& j, const std::string& field) {
    if (!j.is_number_unsigned()) throw OutputError(path + ": " + field + ": expected a whole number");
  };
  if (!c.is_object()) throw OutputError(path + ": expected a JSON object");
  for (const char* k : {"next", "positive", "negative"}) whole(c.contains(k) ? c[k] : json(), k);
  if (!c.contains("files") || !c["files"].is_array()) throw OutputError(path + ": files: expected an array");
  for (size_t i = 0; i < c["files"].size(); ++i) {
    const json& f = c["files"][i];
    const std::string at = "files[" + std::to_string(i) + "]";
    if (!f.is_object() || !f.contains("name") || !f["name"].is_string())
      throw OutputError(path + ": " + at + ".name: expected a string");
    whole(f.contains("bytes") ? f["bytes"] : json(), at + ".bytes");
    whole(f.contains("xxh3") ? f["xxh3"] : json(), at + ".xxh3");
  }
}

}  // namespace

uint64_t manifest_total(const json& spec) {
  return count_field(spec, spec.is_object() && spec.contains("scenarios_count") ? "scenarios_count" : "count", "spec.");
}

json parse_checkpoint(std::string_view text, const std::string& path) {
  json c = parse<OutputError>(text, path, "unreadable checkpoint");
  check_checkpoint(c, path);
  return c;
}

json parse_manifest(std::string_view text, const std::string& path) {
  json m = parse<InputError>(text, path, "not a manifest portalsim wrote");
  try {
    check_manifest(m);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  return m;
}

}  // namespace portalsim
