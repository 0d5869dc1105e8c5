// TOML text in: the byte checks of input_file.h, a nesting cap checked before toml++
// (whose parser recurses) sees the text, syntax errors with line and column, and
// unknown keys named with the nearest known one.
#pragma once
#include <toml++/toml.h>

#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

namespace portalsim::io {

// Arrays and inline tables nest at most this deep.
inline constexpr int kMaxTomlDepth = 32;

// Throws InputError naming source, line and column.
toml::table parse_toml(std::string_view text, const std::string& source);

// Throws InputError naming the first key of `t` that is not in `known`, its line, and
// the known key nearest to it ("mmw_uper: unknown key (did you mean mmw_upper?)").
void reject_unknown_keys(const toml::table& t, std::initializer_list<std::string_view> known, const std::string& source,
                         const std::string& field);
void reject_unknown_keys(const toml::table& t, std::span<const std::string_view> known, const std::string& source,
                         const std::string& field);

}  // namespace portalsim::io
