// rbcontact/compliance.hpp: the contact-surface compliance G = (A^{-1})_{DD}, D = the free dofs that
// the constraint rows can touch (slave and master facet dofs). With G, each Kacanov iterate's dual
// Hessian S = K_D G K_D^T costs dense operations only; computed once per parameter.
// Methods (-contact_compliance): schur (MUMPS Schur complement on D, then G = S_A^{-1}; 1 rank, or
// each rank its block when A has no coupling between ranks: -mesh_partitioner bodies),
// inverse (MUMPS selected entries of A^{-1} on the KSP's parallel factor: several ranks),
// redundant (the same on a sequential copy of A on every rank: several ranks), solves (one parallel
// back-solve per dof of D), auto (schur on 1 rank or with uncoupled ranks, redundant otherwise).
#pragma once
#include <petscmat.h>
#include <vector>
#include "rbcontact/fom.hpp"

namespace rbc {

class SurfaceCompliance {
public:
  // D: global dof indices, sorted, identical on every rank.
  PetscErrorCode Compute(ElasticFOM &fom, const std::vector<PetscInt> &D);
  std::vector<PetscInt>  D;
  std::vector<PetscReal> G; // nD x nD, column-major, on every rank
  std::string            method;
  PetscLogDouble         seconds = 0;
};

} // namespace rbc
