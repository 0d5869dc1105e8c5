// Philox4x32-10 (Salmon et al., "Parallel random numbers: as easy as 1, 2, 3", SC11),
// the counter-based generator behind every random draw, written for the host and the
// reference from docs/model/determinism.md. kernels/lib/philox.cl is the kernels' own
// implementation; tests/philox_test.cpp holds both to the published vectors.
//
// A draw is a pure function of (seed, scenario index, stream, element):
//   key = (seed low 32, seed high 32), counter = (element, stream, index low, index high).
#pragma once
#include <array>
#include <cstdint>

#include "contract.h"

namespace portalsim {

using Philox4 = std::array<uint32_t, 4>;

inline Philox4 philox4x32_10(Philox4 ctr, std::array<uint32_t, 2> key) {
  constexpr uint32_t kM0 = 0xD2511F53u, kM1 = 0xCD9E8D57u;
  constexpr uint32_t kW0 = 0x9E3779B9u, kW1 = 0xBB67AE85u;
  for (int round = 0; round < 10; ++round) {
    const uint64_t p0 = static_cast<uint64_t>(kM0) * ctr[0];
    const uint64_t p1 = static_cast<uint64_t>(kM1) * ctr[2];
    ctr = {static_cast<uint32_t>(p1 >> 32) ^ ctr[1] ^ key[0], static_cast<uint32_t>(p1),
           static_cast<uint32_t>(p0 >> 32) ^ ctr[3] ^ key[1], static_cast<uint32_t>(p0)};
    key[0] += kW0;
    key[1] += kW1;
  }
  return ctr;
}

// Streams (kernels/contract.h): each kind of draw has its own, so adding one never shifts another.
enum Stream : uint32_t {
  kStreamNoisePattern = PS_STREAM_NOISE_PATTERN,
  kStreamMetalNoise = PS_STREAM_METAL_NOISE,
  kStreamPixelNoise = PS_STREAM_PIXEL_NOISE,
  kStreamBlockNoise = PS_STREAM_BLOCK_NOISE,
  kStreamJitter = PS_STREAM_JITTER,
  kStreamRawNoise = PS_STREAM_RAW_NOISE,
  kStreamIrNoise = PS_STREAM_IR_NOISE,
  kStreamTransform = PS_STREAM_TRANSFORM,
  kStreamFeatureNoise = PS_STREAM_FEATURE_NOISE,
  kStreamPixelNoiseFast = PS_STREAM_PIXEL_NOISE_FAST,
  kStreamKnobDraw = PS_STREAM_KNOB_DRAW,
  kStreamBodies = PS_STREAM_BODIES,
  kStreamGenerate = PS_STREAM_GENERATE,
};

inline Philox4 draw(uint64_t seed, uint64_t index, uint32_t stream, uint32_t element) {
  return philox4x32_10({element, stream, static_cast<uint32_t>(index), static_cast<uint32_t>(index >> 32)},
                       {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)});
}

// Uniform in [0, 1) with 24 bits: exact in float and in double, so both backends agree.
inline double uniform24(uint32_t r) { return static_cast<double>(r >> 8) * (1.0 / 16777216.0); }
// Uniform integer in [0, n) without division: the high word of r * n.
inline uint32_t below(uint32_t r, uint32_t n) { return static_cast<uint32_t>((static_cast<uint64_t>(r) * n) >> 32); }

}  // namespace portalsim
