#include "build_config.h"

namespace portalsim::test {

const char* const kBinary = PORTALSIM_BINARY;
const int kTimeScale = PORTALSIM_TIME_SCALE;
#ifdef PORTALSIM_SANITIZED
const bool kSanitized = true;
#else
const bool kSanitized = false;
#endif

}  // namespace portalsim::test
