// The kernels' table Gaussians (kernels/shared.h, PS_GAUSS_ELEMENT): entry k is
// Phi^-1((k + 1/2) / PS_GAUSS_TABLE), the standard normal quantile at the middle of the
// k-th of PS_GAUSS_TABLE (4,096) equally likely slices.
#pragma once
#include <vector>

namespace portalsim {

const std::vector<double>& gauss_table();

}  // namespace portalsim
