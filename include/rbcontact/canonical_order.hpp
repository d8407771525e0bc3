// rbcontact/canonical_order.hpp: a partition-independent numbering of the free dofs and of the contact
// multipliers, so that snapshots stored on 1 or N ranks (or any subcommunicator) are identical arrays.
// Dofs are ordered by (body, coordinates of the point carrying the dof, component); multipliers by the
// coordinates of their slave vertex. Coordinates are those of the reference mesh file, the same on
// every partition; within one body no two points share coordinates.
#pragma once
#include <petscvec.h>
#include <vector>
#include "rbcontact/elasticity.hpp"

namespace rbc {

class CanonicalOrder {
public:
  // Builds the numbering of the global (free) dofs of elas's DM. Collective.
  PetscErrorCode BuildDofs(const Elasticity &elas);
  // Builds the numbering of a distributed vector whose entry i sits at coordinates coord[d][i] (the
  // multipliers: ContactSystem::coord). Collective.
  PetscErrorCode BuildMultipliers(const Vec coord[], PetscInt dim);
  // Entries of a global dof vector / multiplier vector in canonical order, on rank 0 of the vector's
  // communicator (empty elsewhere).
  PetscErrorCode DofsToCanonical(Vec v, std::vector<PetscReal> *out) const;
  PetscErrorCode MultipliersToCanonical(Vec v, std::vector<PetscReal> *out) const;
  // Canonical index of global dof g (any g, every rank).
  PetscInt CanonicalDof(PetscInt g) const { return dofCanon_[g]; }
  PetscInt CanonicalMultiplier(PetscInt r) const { return multCanon_[r]; }
  PetscInt NumDofs() const { return (PetscInt)dofCanon_.size(); }
  PetscInt NumMultipliers() const { return (PetscInt)multCanon_.size(); }

private:
  std::vector<PetscInt> dofCanon_;  // global dof -> canonical position (every rank)
  std::vector<PetscInt> multCanon_; // global multiplier row -> canonical position (every rank)
};

} // namespace rbc
