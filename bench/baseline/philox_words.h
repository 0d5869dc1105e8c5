// Philox4x32-10 for the baselines, words 0 and 1 of the result, for the counter
// (element, stream, index) and key seed: the generator of host/scene/philox.h, written
// out so that the baselines share no code with the kernels or the reference.
#pragma once
#include <cstdint>

namespace portalsim::baseline {

inline void philox_words(uint32_t element, uint32_t stream, uint64_t index, uint64_t seed, uint32_t& r0, uint32_t& r1) {
  uint32_t c0 = element, c1 = stream, c2 = static_cast<uint32_t>(index), c3 = static_cast<uint32_t>(index >> 32);
  uint32_t k0 = static_cast<uint32_t>(seed), k1 = static_cast<uint32_t>(seed >> 32);
  for (int r = 0; r < 10; ++r) {
    const uint64_t p0 = static_cast<uint64_t>(c0) * 0xD2511F53u, p1 = static_cast<uint64_t>(c2) * 0xCD9E8D57u;
    const uint32_t n0 = static_cast<uint32_t>(p1 >> 32) ^ c1 ^ k0, n2 = static_cast<uint32_t>(p0 >> 32) ^ c3 ^ k1;
    c1 = static_cast<uint32_t>(p1);
    c3 = static_cast<uint32_t>(p0);
    c0 = n0;
    c2 = n2;
    k0 += 0x9E3779B9u;
    k1 += 0xBB67AE85u;
  }
  r0 = c0;
  r1 = c1;
}

}  // namespace portalsim::baseline
