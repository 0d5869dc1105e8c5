// The kernels' table Gaussians (kernels/shared.h, PS_GAUSS_ELEMENT): entry k is
// Phi^-1((k + 1/2) / 65536), the standard normal quantile at the middle of the k-th of
// 65,536 equally likely slices.
#pragma once
#include <vector>

namespace portalsim {

const std::vector<double>& gauss_table();

}  // namespace portalsim
