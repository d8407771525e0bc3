// rbcontact/warm_start.hpp: where the online reduced Kacanov loop starts. The ROM file stores the reduced
// solutions (v, lambda) at the training parameters; the start at mu is a combination sum_k w_k (v_k,
// lambda_k) of them with weights summing to 1:
//   - one parameter: the linear interpolation between the two training parameters that bracket mu (the
//     nearest one outside the training range);
//   - several parameters: the affine least-squares fit over the 2 np + 1 nearest training parameters
//     (distances scaled by the box), evaluated at mu: exact when the solution is affine in mu, second
//     order on a grid; the nearest one when those points do not determine an affine fit.
// The multipliers combined this way may leave the cone: the caller clips them at 0.
#pragma once
#include <petscsys.h>
#include <utility>
#include <vector>

namespace rbc {

// mus: the training parameters (nw x np, row-major); width: the box widths (np). Returns (index, weight)
// pairs with weights summing to 1 (empty when there is no training parameter).
std::vector<std::pair<size_t, PetscReal>> WarmStartWeights(const std::vector<PetscReal> &mus, const std::vector<PetscReal> &width, const std::vector<PetscReal> &mu);

} // namespace rbc
