// rbcontact/tao_recipe.hpp: the measured TAO BQPIP settings for our bound-constrained QPs
// (../shared/notes/nnls-with-bqpip.md): absolute gradient test only (the relative one fires
// spuriously), gatol 1e-7 (BQPIP's measure stalls near 3e-8), at most 200 iterations, an inner
// Cholesky solve. One place for the dual QP of the FOM, the NNLS of the dual bases and the reduced QP.
#pragma once
#include <petsctao.h>

namespace rbc {
// Sets type BQPIP, the tolerances and the inner KSP/PC on tao (before TaoSetFromOptions, so that the
// options of its prefix still override everything).
PetscErrorCode TaoBQPIPRecipe(Tao tao);

// The quadratic objective 1/2 x'Hx - c'x with gradient Hx - c and the constant Hessian H (filled in
// before TaoSolve). q must outlive the solves.
struct TaoQuadratic {
  Mat H = nullptr;
  Vec c = nullptr;
};
PetscErrorCode TaoSetQuadratic(Tao tao, TaoQuadratic *q);
} // namespace rbc
