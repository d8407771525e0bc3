// src/apps/stages.hpp: one function per stage of the rbcontact executable.
#pragma once
#include <petscsys.h>

namespace rbc {
PetscErrorCode StageFom(MPI_Comm comm);
PetscErrorCode StageOffline(MPI_Comm comm);
PetscErrorCode StageDualBasis(MPI_Comm comm);
PetscErrorCode StageOnline(MPI_Comm comm);
PetscErrorCode StageValidate(MPI_Comm comm);
PetscErrorCode StageProbe(MPI_Comm comm);
} // namespace rbc
