// The reference's mappings from a Philox draw to a value, written from the random-stream
// contract (docs/model/determinism.md) and shared with the kernels only through its
// constants (kernels/contract.h): the kernels implement each mapping on their own.
#pragma once
#include <cstdint>

namespace portalsim::reference {

// The standard normal quantile Phi^-1(q), q in (0, 1), to double precision.
double normal_quantile(double q);

// The physics model's table Gaussian of cell p (row by row) of view `view`'s field in
// `stream`: the top 12 bits k of one 16-bit half of one word of one draw, taken to
// Phi^-1((k + 1/2) / 4096).
double table_gaussian(uint64_t seed, uint64_t index, uint32_t stream, int view, int p);

// The physics fast tier's draw of the same cell: that half's two bytes summed, s in 0..510,
// t = (s - 255) / 255, bent to a near-normal by the odd quintic PS_IH_C1 t + PS_IH_C3 t^3 +
// PS_IH_C5 t^5 (kernels/contract.h).
double fast_gaussian(uint64_t seed, uint64_t index, uint32_t stream, int view, int p);

// The thesis model's per-pixel sensor noise of pixel p of view `view`: Box-Muller over the
// first two words of the draw of pixel pair p / 2, cosine for even p, sine for odd.
double pixel_gaussian(uint64_t seed, uint64_t index, int view, int p);

// The thesis model's per-pixel sensor noise under noise_draw irwin-hall (the fast tier), pixel
// p of view `view`: the table Gaussians' 16-bit half of p in stream PS_STREAM_PIXEL_NOISE_FAST,
// its two bytes summed to s, t = (s - 255) / 255, g = t (C1 + t^2 (C3 + t^2 C5)).
double pixel_irwin_hall(uint64_t seed, uint64_t index, int view, int p);

// The block-mean noise model's draw of feature q of a row (the thesis fast tier's features-only
// runs with pixel noise): Box-Muller over the first two words of the draw of element
// q - q % 2 in stream PS_STREAM_BLOCK_NOISE, cosine for even q, sine for odd.
double block_mean_gaussian(uint64_t seed, uint64_t index, int q);

}  // namespace portalsim::reference
