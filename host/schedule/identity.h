// A run's identity (version, catalogue, spec, shard): what a resume, a merge and a
// ranked run compare before they trust what a folder holds.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace portalsim {

// "spec.seed (1 there, 2 now), spec.count (...)": every entry that differs, one level
// into objects; empty when equal.
std::string differing_keys(const nlohmann::json& was, const nlohmann::json& now, const std::string& prefix = "");

}  // namespace portalsim
