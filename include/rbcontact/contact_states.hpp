// rbcontact/contact_states.hpp: the contact states of the offline hyper-reduction (the training solutions and the
// reduced Kacanov iterates at which the cubature is fitted), kept by the points' terms instead of their kappa rows.
// A point's row is kappa(p, :) = sum_t coef_t theta(row_t, :) over at most 2 x nodes x dim terms (18 in 3D P1,
// 8 in 2D P1: ContactPatch::EvaluateCoefficients), 12 bytes a term, against the N doubles of the row: the store does
// not grow with N (measured: 0.58 of the dense arrays on the 3D default mesh, N 44; about the same size in 2D with
// N 13; by the count about 1/5 for N ~ 150-200 on the fine 3D meshes; docs/hyper_reduction.md, "Memory"). A state's
// Q x N block is formed on demand by ContactPatch::KappaRow, the kernel Evaluate uses, so the blocks are bit for bit
// those of Evaluate. Also kept: gamma and w n2 per point (Q and Q x dim doubles a state).
// Implementation: src/offline/contact_states.cpp.
#pragma once
#include <petscsys.h>
#include <cstdint>
#include <vector>
#include "rbcontact/reduced_contact.hpp"

namespace rbc {

class ContactStates {
public:
  // States of the points 0..Q-1 of patch (its theta combines the terms: it must outlive the store).
  // expected: the number of states to come (0: unknown), storage reserved for them from the first one's size.
  explicit ContactStates(const ContactPatch &patch, PetscInt expected = 0) : patch_(&patch), Q_(patch.NumPoints()), expected_(expected) {}
  // Append the state the patch holds now (geometry and displacement set); hit (Q): the master facet each point found.
  void Append(std::vector<PetscInt> *hit);
  PetscInt Size() const { return (PetscInt)base_.size(); }
  // The kappa block of state s (Q x N, row-major) in a buffer that the next call overwrites.
  const PetscReal *Kappa(PetscInt s) const;
  // y(p) = kappa_s(p, :) . v for every point from thetaV = theta v (one value per patch dof): the terms' combination
  // without forming the block (the lambda fit's constraint values, docs/hyper_reduction.md), equal to Kappa(s) v to rounding.
  void KappaTimes(PetscInt s, const PetscReal *thetaV, PetscReal *y) const;
  // Every state's gamma (Size() blocks of Q) and w n2 (Size() blocks of Q x dim), contiguous.
  const std::vector<PetscReal> &Gamma() const { return gamma_; }
  const std::vector<PetscReal> &ForceWeights() const { return wn_; }
  // Bytes held (the terms, offsets, gamma, w n2; not the block buffer).
  size_t Bytes() const;

private:
  const ContactPatch   *patch_;
  PetscInt              Q_, expected_;
  std::vector<size_t>   base_;   // per state: its first term
  std::vector<uint32_t> start_;  // per state and point (Q + 1 a state): its first term after base_
  std::vector<PetscInt> row_;    // per term: the patch dof
  std::vector<PetscReal> coef_, gamma_, wn_;
  mutable std::vector<PetscReal> block_;
};

} // namespace rbc
