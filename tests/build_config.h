// What differs between the builds the suite is compiled into. Only tests/build_config.cpp
// is compiled with each build's definitions (CMakeLists.txt): every other test file is the
// same in the Release and the sanitizer build, so ccache gives the second build the first's
// objects (.ci/run builds both).
#pragma once

namespace portalsim::test {

// The build's own portalsim.
extern const char* const kBinary;

// How many times slower the build under test runs than a Release build (the sanitizer
// build's factor is set in CMakeLists.txt). Every limit on how long a child may run is a
// hang detector, never a speed check; each is multiplied by this factor, so that a slower
// build cannot miss one.
extern const int kTimeScale;

// .ci/run's second pass builds the tests with AddressSanitizer and UndefinedBehaviorSanitizer
// (PORTALSIM_SANITIZE), where the fp64 reference's loops run several times slower. The
// sanitizers check the host C++, which a few scenarios walk through as many do: the parity
// tests whose time is those loops take every fourth scenario of their set there, which
// keeps its mix of single objects and crowds (the Release pass, .ci/run's first, runs them
// whole).
extern const bool kSanitized;

}  // namespace portalsim::test
