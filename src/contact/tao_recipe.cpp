// src/contact/tao_recipe.cpp: the TAO BQPIP settings of ../shared/notes/nnls-with-bqpip.md.
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

} // namespace rbc
