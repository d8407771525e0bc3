// rbcontact/affine_decomposition.hpp: A(mu) = sum_q thetaA_q(mu) A_q and f(mu) = sum_q thetaF_q(mu) f_q
// on the reference mesh, derived automatically from the scene: the effective tensor of every body
// under its map G_b(mu) and material E_b(mu), nu_b(mu), the Dirichlet lifting, body forces and
// tractions. Coefficient functions are sampled over the parameter box; identically zero ones are
// dropped, proportional ones (constants included) merged into one term: "model only what a scene
// needs". Each term keeps a description of why it exists (report key affine_terms).
#pragma once
#include <petscmat.h>
#include <string>
#include <vector>
#include "rbcontact/elasticity.hpp"
#include "rbcontact/report.hpp"

namespace rbc {

// A coefficient function: the product of the factors that are set, times scale.
struct Coefficient {
  PetscInt  tensorBody = -1, tensorEntry = -1; // effective tensor entry of a body (aux index)
  PetscInt  detBody    = -1;                   // |det G_b(mu)|
  PetscInt  surfBody   = -1;                   // s_b(mu)^(dim-1) (conformal maps)
  PetscInt  param      = -1;                   // mu[param] / default
  PetscReal scale      = 1.0;
  PetscReal Evaluate(const Elasticity &elas, const GeometryMap *map, const std::vector<PetscReal> &mu) const;
  std::string Describe(const SceneSpec &scene) const;
};

class AffineDecomposition {
public:
  AffineDecomposition() = default;
  AffineDecomposition(const AffineDecomposition &) = delete;
  AffineDecomposition &operator=(const AffineDecomposition &) = delete;
  ~AffineDecomposition();

  // Builds the terms (assembles A_q and f_q on elas's DM). -affine_samples n sets the sample count.
  PetscErrorCode Build(Elasticity &elas, const GeometryMap *map);
  std::vector<PetscReal> ThetaA(const std::vector<PetscReal> &mu) const;
  std::vector<PetscReal> ThetaF(const std::vector<PetscReal> &mu) const;
  // A(mu), f(mu) from the terms; creates A and f on the first call (same pattern as A_q).
  PetscErrorCode Assemble(const std::vector<PetscReal> &mu, Mat *A, Vec *f) const;
  void Describe(JsonValue *out) const; // {"A": n, "f": m, "A_terms": [...], "f_terms": [...]}
  // r = A(mu) u - f(mu) from the terms, without forming A(mu) (t: a work vector like u).
  PetscErrorCode Residual(const std::vector<PetscReal> &mu, Vec u, Vec t, Vec r) const;

  std::vector<Mat>         Aq;
  std::vector<Vec>         fq;
  std::vector<Coefficient> thetaA, thetaF;
  std::vector<std::string> whyA, whyF;

private:
  const Elasticity  *elas_ = nullptr;
  const GeometryMap *map_  = nullptr;
};

} // namespace rbc
