// src/contact/tao_recipe.cpp: the TAO BQPIP settings of ../shared/notes/nnls-with-bqpip.md and the
// dense quadratic objective the bound-constrained QPs hand to TAO.
#include "rbcontact/tao_recipe.hpp"

namespace rbc {

PetscErrorCode TaoBQPIPRecipe(Tao tao)
{
  KSP ksp;
  PC  pc;

  PetscFunctionBeginUser;
  PetscCall(TaoSetType(tao, TAOBQPIP));
  PetscCall(TaoSetTolerances(tao, 1e-7, 0.0, 0.0));
  PetscCall(TaoSetMaximumIterations(tao, 200));
  PetscCall(TaoGetKSP(tao, &ksp));
  if (ksp) {
    PetscCall(KSPSetType(ksp, KSPPREONLY));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCSetType(pc, PCCHOLESKY));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode QuadraticObjGrad(Tao, Vec x, PetscReal *f, Vec g, void *ctx)
{
  const TaoQuadratic *q = static_cast<const TaoQuadratic *>(ctx);
  PetscScalar         xHx, cx;

  PetscFunctionBeginUser;
  PetscCall(MatMult(q->H, x, g));
  PetscCall(VecDot(x, g, &xHx));
  PetscCall(VecDot(x, q->c, &cx));
  *f = 0.5 * PetscRealPart(xHx) - PetscRealPart(cx);
  PetscCall(VecAXPY(g, -1.0, q->c));
  PetscFunctionReturn(0);
}

static PetscErrorCode ConstantHessian(Tao, Vec, Mat, Mat, void *)
{
  PetscFunctionBeginUser;
  PetscFunctionReturn(0);
}

PetscErrorCode TaoSetQuadratic(Tao tao, TaoQuadratic *q)
{
  PetscFunctionBeginUser;
  PetscCall(TaoSetObjectiveAndGradient(tao, NULL, QuadraticObjGrad, q));
  PetscCall(TaoSetHessian(tao, q->H, q->H, ConstantHessian, NULL));
  PetscFunctionReturn(0);
}

} // namespace rbc
