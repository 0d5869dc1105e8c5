#include "scene/scene.h"

#include "base/error.h"

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
    std::string known;
    for (const Object& o : cat.objects) known += (known.empty() ? "" : ", ") + o.name;
    throw InputError(where + ": unknown object \"" + name + "\" (known: " + known + ", none)");
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
