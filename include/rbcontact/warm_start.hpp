// rbcontact/warm_start.hpp: where the online reduced Kacanov loop starts. The ROM file stores the reduced
// solutions (v, lambda) at the training parameters; the start at mu is a combination sum_k w_k (v_k,
// lambda_k) of them with weights summing to 1:
//   - one parameter: the linear interpolation between the two training parameters that bracket mu (the
//     nearest one outside the training range);
//   - several parameters (-rom_warm_start_degree 2, the default): the quadratic least-squares fit over
//     the 2 m - 1 nearest training parameters (m = (np + 1)(np + 2) / 2 monomials; 3 m, then 5 m when
//     those do not determine it), evaluated at mu; exact for quadratic data, third order on a grid;
//     else (or with degree 1) the affine fit over the 2 np + 1 nearest (distances scaled by the box);
//     the nearest one when those points do not determine an affine fit. half_disks (9 x 9 grid): mean
//     Kacanov iterates 2.75 -> 2.4, median online time 367 -> 252 us (docs/online.md).
// The multipliers combined this way may leave the cone: the caller clips them at 0.
#pragma once
#include <petscsys.h>
#include <utility>
#include <vector>

namespace rbc {

// mus: the training parameters (nw x np, row-major); width: the box widths (np). Returns (index, weight)
// pairs with weights summing to 1 (empty when there is no training parameter). degree: 1 or 2 (several
// parameters only).
std::vector<std::pair<size_t, PetscReal>> WarmStartWeights(const std::vector<PetscReal> &mus, const std::vector<PetscReal> &width, const std::vector<PetscReal> &mu, int degree = 1);

} // namespace rbc
