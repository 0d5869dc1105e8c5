#include "scene/scene.h"

#include <algorithm>

#include "base/error.h"
#include "base/spoken_list.h"

namespace portalsim {

int16_t parse_object_token(const Catalogue& cat, const std::string& token, const std::string& where) {
  std::string name = token, code;
  if (const size_t colon = token.find(':'); colon != std::string::npos) {
    name = token.substr(0, colon);
    code = normalise_name(token.substr(colon + 1));
    if (code.empty()) throw InputError(where + ": \"" + token + "\": empty orientation after ':' (use :h or :v)");
    if (code == "horizontal") code = "h";
    if (code == "vertical") code = "v";
  }
  if (normalise_name(name) == "none") {
    if (!code.empty()) throw InputError(where + ": \"" + token + "\": an empty region has no orientation");
    return kNoObject;
  }
  const int obj = cat.find_object(name);
  if (obj < 0) {
    throw InputError(where + ": unknown object \"" + name + "\" (known: " + cat.object_names() + ", none)");
  }
  const Object& o = cat.objects[obj];
  if (code.empty()) return static_cast<int16_t>(o.first_variant);
  for (size_t k = 0; k < o.variants.size(); ++k)
    if (o.variants[k].code == code) return static_cast<int16_t>(o.first_variant + k);
  std::string known;
  for (const Variant& v : o.variants)
    if (!v.code.empty()) known += (known.empty() ? "" : ", ") + v.code;
  throw InputError(where + ": object " + o.name + " has no orientation \"" + token.substr(token.find(':') + 1) + "\"" +
                   (known.empty() ? " (it has a single drawing)" : " (it has: " + known + ")"));
}

bool is_object_set_token(const std::string& token) {
  const size_t colon = token.find(':');
  if (colon == std::string::npos) return false;
  const std::string key = normalise_name(token.substr(0, colon));
  return key == "class" || key == "family";
}

std::vector<int> parse_object_set(const Catalogue& cat, const std::string& token, const std::string& where,
                                  bool allow_all) {
  std::vector<int> out;
  if (allow_all && normalise_name(token) == "all") {
    for (size_t o = 0; o < cat.objects.size(); ++o) out.push_back(static_cast<int>(o));
    return out;
  }
  if (!is_object_set_token(token)) {
    const int o = cat.find_object(token);
    if (o < 0)
      throw InputError(where + ": unknown object \"" + token + "\" (known: " + cat.object_names() +
                       (allow_all ? "; or all, class:NAME, family:NAME)" : "; or class:NAME, family:NAME)"));
    return {o};
  }
  const size_t colon = token.find(':');
  const bool by_class = normalise_name(token.substr(0, colon)) == "class";
  const std::string want = normalise_name(token.substr(colon + 1));
  std::vector<std::string> known;
  for (size_t o = 0; o < cat.objects.size(); ++o) {
    const std::string& name = by_class ? cat.objects[o].object_class : cat.objects[o].family;
    if (name.empty()) continue;
    if (!want.empty() && normalise_name(name) == want) out.push_back(static_cast<int>(o));
    if (std::find(known.begin(), known.end(), name) == known.end()) known.push_back(name);
  }
  if (out.empty())
    throw InputError(where + ": no object has " + (by_class ? "class" : "family") + " \"" + token.substr(colon + 1) +
                     "\" (the catalogue's " + (by_class ? "classes" : "families") + ": " +
                     (known.empty() ? std::string("none") : spoken_list(known)) + ")");
  return out;
}

Scenario parse_object_list(const Catalogue& cat, const std::vector<std::string>& tokens) {
  if (tokens.size() > cat.regions.size())
    throw InputError("objects: " + std::to_string(tokens.size()) + " objects given, but there are only " +
                     std::to_string(cat.regions.size()) + " regions (one object per region, \"none\" for empty)");
  Scenario s;
  for (size_t i = 0; i < tokens.size(); ++i)
    s.objects[i] = parse_object_token(cat, tokens[i], "objects: region " + std::to_string(i + 1));
  return s;
}

}  // namespace portalsim
