// `portalsim bench`'s output: the speed table as Markdown, or the same as JSON.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "speed/run.h"

namespace portalsim::speed {

// Medians, ratios to the plain loop (computed from the medians), shares of the measured
// memory and disk write rates.
nlohmann::json report_json(const BenchReport& r);
// The same as Markdown tables with a header and notes.
std::string report_text(const BenchReport& r);
// "1.38M/s", "12.8k/s", "317/s".
std::string format_rate(double per_s);

}  // namespace portalsim::speed
