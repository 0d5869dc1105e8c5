// A folder made by `portalsim generate` as `evaluate` reads it: its feature table (any
// format generate writes features to, through validate's readers), the labels, which
// sensor each column belongs to, and per region whether it holds a threat (from
// scenarios.csv and the manifest's rule). Bad input is an InputError naming the file and
// the field.
#pragma once
#include <array>
#include <nlohmann/json.hpp>
#include <string>

#include "evaluate/evaluation.h"
#include "scene/catalogue.h"
#include "scene/rules.h"

namespace portalsim::cli {

struct EvaluateData {
  evaluate::Dataset data;
  nlohmann::json about;  // source, table, rule, how the region labels were made, the regions' places
};

EvaluateData read_evaluate_data(const std::string& dir, const Catalogue& cat);

// Per region of `s`: whether its object takes part in a threat under `rule`: the rule holds
// for that object alone, or the scenario is a threat (`threat`) and no longer is without it.
std::array<uint8_t, kMaxRegions> region_threats(const ThreatRule& rule, const Scenario& s, bool threat);

}  // namespace portalsim::cli
