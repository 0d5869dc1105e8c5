// One libFuzzer target per parser: PORTALSIM_FUZZ_TARGET names it (CMakeLists.txt).
#include "targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string target = PORTALSIM_FUZZ_TARGET;
  portalsim::fuzz::run_target(target, data, size);
  return 0;
}
