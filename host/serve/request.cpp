#include "serve/request.h"

#include <cctype>
#include <limits>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "base/error.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "serve/knob_fields.h"

namespace portalsim {

namespace {

using nlohmann::json;

// A field of the request, checked for type; errors name it as the command line would.
template <class T>
T field(const json& j, const char* name, const T& fallback) {
  if (!j.contains(name) || j[name].is_null()) return fallback;
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    if (!j[name].is_number_integer())
      throw InputError(std::string("request: field \"") + name + "\" is not a whole number");
    // Out-of-range values become a range error of their own field, never a wrap.
    if (j[name].is_number_unsigned() ? j[name].get<uint64_t>() > uint64_t(std::numeric_limits<T>::max())
                                     : j[name].get<int64_t>() < int64_t(std::numeric_limits<T>::min()))
      throw InputError(std::string("request: field \"") + name + "\" is out of range");
  }
  try {
    return j[name].get<T>();
  } catch (const json::exception&) {
    throw InputError(std::string("request: field \"") + name + "\" has the wrong type");
  }
}

}  // namespace

Request parse_request(const Catalogue& cat, std::string_view body) {
  const json j = json::parse(body, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw InputError("request: the body is not a JSON object");
  Request r;
  r.in.subject = field<int>(j, "subject", 1);
  r.in.objects = field<std::vector<std::string>>(j, "objects", {});
  r.in.rule = field<std::string>(j, "rule", "");
  r.in.threat = field<std::string>(j, "threat", "");
  r.seed = field<std::string>(j, "seed", "0");
  r.tier = field<std::string>(j, "tier", "standard");
  if (r.in.objects.size() > cat.regions.size())
    throw InputError("objects: " + std::to_string(r.in.objects.size()) + " given, at most " +
                     std::to_string(cat.regions.size()) + " regions");
  r.plan.model.seed = io::parse_u64(r.seed, "--seed");
  // The command line's own check (CLI11's IsMember) and its words.
  if (r.tier != "fast" && r.tier != "standard" && r.tier != "exact")
    throw InputError("--tier: " + r.tier + " not in {fast,standard,exact}");
  r.plan.fidelity = tier_fidelity(parse_tier(r.tier, "--tier"));
  apply_knobs(j, r.plan);  // every knob of the registry, checked as its flag is; after the tier
  validate(r.plan, cat);
  r.scene = make_scenario(cat, r.in);
  r.name = field<std::string>(j, "name", "");
  r.count = field<int64_t>(j, "count", 0);
  return r;
}

std::string check_name(const std::string& name, const char* what) {
  const std::string w = std::string(what) + ": \"" + name + "\" ";
  if (name.empty()) throw InputError(std::string(what) + ": empty name");
  if (name.size() > 100) throw InputError(w + "is longer than 100 characters");
  if (name[0] == '/') throw InputError(w + "is an absolute path; give a name inside --root");
  if (name.find("..") != std::string::npos) throw InputError(w + "contains \"..\"; give a name inside --root");
  if (name.find('/') != std::string::npos) throw InputError(w + "contains \"/\"; give one folder name");
  if (name[0] == '.') throw InputError(w + "starts with \".\"");
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'))
      throw InputError(w + "may only use letters, digits, '-', '_' and '.'");
  return name;
}

}  // namespace portalsim
