// The parsers fuzzed (tests/fuzz/fuzz_main.cpp) and replayed by ctest (input_test.cpp).
// Each takes arbitrary bytes; bad input must end in InputError (OutputError for a run's
// own state files), anything else escapes.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace portalsim::fuzz {

// Target names, also the folder names under tests/fuzz/corpus/ and tests/fuzz/crashes/.
const std::vector<std::string>& target_names();

// Runs `target` on the bytes; returns true when they parsed, false on InputError or OutputError.
bool run_target(const std::string& target, const uint8_t* data, size_t size);

}  // namespace portalsim::fuzz
