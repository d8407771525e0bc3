// src/contact/kacanov_newton.cpp: the Newton step of the full-order Kacanov loop on the contact-dof
// displacement x (the fixed point x = F(x), docs/fom_speed.md "Newton on the contact dofs"). With the
// active set A of the QP at x fixed, the image is F(x) = u0 - G K(x)^T lambda(x) with K_A(x) F(x) = g_A(x),
// so its Jacobian is
//   J dx = -P G H dx + G K_A^T S_AA^{-1} Q_A dx,   P = I - G K_A^T S_AA^{-1} K_A,   S_AA = K_A G K_A^T,
// H = d(K^T lambda)/dx (geometric stiffness) and Q = d(g - K y)/dx at y = F(x) (ContactMap::AssembleTangent).
// J has nonzero columns only on the dofs C that the active zone's geometry depends on, so the step
// (I - J) dx = F(x) - x is solved through the |C| x |C| system (I - J_CC) z = r_C, dx = r + J_:C z.
// Dense, serial and deterministic: every rank computes the same step from the same gathered data.
#include "rbcontact/kacanov.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>

namespace rbc {

PetscErrorCode KacanovNewtonStep(const KacanovNewtonData &in, PetscReal maxRatio, std::vector<PetscReal> *next, KacanovNewtonInfo *info)
{
  const PetscInt nD = (PetscInt)in.D->size(), R = in.R;

  PetscFunctionBeginUser;
  *info          = KacanovNewtonInfo();
  info->accepted = false;
  std::vector<PetscInt> act; // the active rows
  for (PetscInt i = 0; i < R; ++i)
    if (in.lam[i] > 0) act.push_back(i);
  const PetscInt nA = (PetscInt)act.size();
  info->active      = nA;
  if (!nA) {
    info->reason = "no active constraint";
    PetscFunctionReturn(0);
  }
  std::vector<PetscInt> rowA(R, -1);
  for (PetscInt a = 0; a < nA; ++a) rowA[act[a]] = a;
  auto dIndex = [&](PetscInt dof) -> PetscInt {
    const auto it = std::lower_bound(in.D->begin(), in.D->end(), dof);
    return it != in.D->end() && *it == dof ? (PetscInt)(it - in.D->begin()) : -1;
  };
  // the columns C (contact dofs the geometry of the active zone depends on)
  const ContactTangent &tan = *in.tan;
  std::vector<PetscInt> C;
  for (PetscInt c : tan.hCol) C.push_back(c);
  for (size_t e = 0; e < tan.qCol.size(); ++e)
    if (rowA[tan.qRow[e]] >= 0) C.push_back(tan.qCol[e]);
  std::sort(C.begin(), C.end());
  C.erase(std::unique(C.begin(), C.end()), C.end());
  const PetscInt nC = (PetscInt)C.size();
  info->columns     = nC;
  if (!nC) {
    info->reason = "no geometric term";
    PetscFunctionReturn(0);
  }
  std::vector<PetscInt> cD(nC); // D index of column c
  for (PetscInt c = 0; c < nC; ++c) {
    cD[c] = dIndex(C[c]);
    PetscCheck(cD[c] >= 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Newton step: tangent column %" PetscInt_FMT " outside the contact dofs", C[c]);
  }
  auto cIndex = [&](PetscInt dof) { return (PetscInt)(std::lower_bound(C.begin(), C.end(), dof) - C.begin()); };
  // GH = G H_:C (nD x nC)
  std::vector<PetscReal> GH((size_t)nD * nC, 0.0);
  for (size_t e = 0; e < tan.hRow.size(); ++e) {
    const PetscInt j = dIndex(tan.hRow[e]);
    PetscCheck(j >= 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Newton step: tangent row %" PetscInt_FMT " outside the contact dofs", tan.hRow[e]);
    const PetscReal  v = tan.hVal[e];
    const PetscReal *g = in.G + (size_t)j * nD; // G is symmetric: column j
    PetscReal       *o = &GH[(size_t)cIndex(tan.hCol[e]) * nD];
    for (PetscInt q = 0; q < nD; ++q) o[q] += v * g[q];
  }
  // B = K_A GH + Q_A (nA x nC), the right-hand side of S_AA Z = B
  std::vector<PetscReal> B((size_t)nA * nC, 0.0);
  for (PetscInt a = 0; a < nA; ++a) {
    const PetscInt i = act[a];
    for (PetscInt e = in.KD->ptr[i]; e < in.KD->ptr[i + 1]; ++e) {
      const PetscInt  q = in.KD->col[e];
      const PetscReal k = in.KD->val[e];
      for (PetscInt c = 0; c < nC; ++c) B[a + (size_t)c * nA] += k * GH[q + (size_t)c * nD];
    }
  }
  for (size_t e = 0; e < tan.qRow.size(); ++e) {
    const PetscInt a = rowA[tan.qRow[e]];
    if (a >= 0) B[a + (size_t)cIndex(tan.qCol[e]) * nA] += tan.qVal[e];
  }
  // Z = S_AA^{-1} B (Cholesky)
  {
    std::vector<PetscReal> SA((size_t)nA * nA);
    for (PetscInt b = 0; b < nA; ++b)
      for (PetscInt a = 0; a < nA; ++a) SA[a + (size_t)b * nA] = in.S[act[a] + (size_t)act[b] * R];
    PetscBLASInt n = (PetscBLASInt)nA, nrhs = (PetscBLASInt)nC, info2 = 0;
    LAPACKpotrf_("L", &n, SA.data(), &n, &info2);
    if (info2) {
      info->reason = "S_AA not positive definite";
      PetscFunctionReturn(0);
    }
    LAPACKpotrs_("L", &n, &nrhs, SA.data(), &n, B.data(), &n, &info2);
    if (info2) {
      info->reason = "S_AA solve failed";
      PetscFunctionReturn(0);
    }
  }
  // J_:C = -GH + T_A Z (nD x nC), T = G K_D^T
  std::vector<PetscReal> J(GH);
  for (auto &v : J) v = -v;
  for (PetscInt c = 0; c < nC; ++c) {
    PetscReal *o = &J[(size_t)c * nD];
    for (PetscInt a = 0; a < nA; ++a) {
      const PetscReal  z = B[a + (size_t)c * nA];
      const PetscReal *t = in.T + (size_t)act[a] * nD;
      if (z != 0.0)
        for (PetscInt q = 0; q < nD; ++q) o[q] += z * t[q];
    }
  }
  // (I - J_CC) z = r_C, dx = r + J_:C z
  std::vector<PetscReal> r(nD), M((size_t)nC * nC), z(nC);
  PetscReal              nr = 0;
  for (PetscInt q = 0; q < nD; ++q) {
    r[q] = in.Fx[q] - in.x[q];
    nr += r[q] * r[q];
  }
  nr = std::sqrt(nr);
  for (PetscInt c = 0; c < nC; ++c) {
    z[c] = r[cD[c]];
    for (PetscInt b = 0; b < nC; ++b) M[b + (size_t)c * nC] = (b == c) - J[cD[b] + (size_t)c * nD];
  }
  {
    PetscBLASInt              n = (PetscBLASInt)nC, one = 1, info2 = 0;
    std::vector<PetscBLASInt> piv(nC);
    LAPACKgetrf_(&n, &n, M.data(), &n, piv.data(), &info2);
    if (info2) {
      info->reason = "I - J singular";
      PetscFunctionReturn(0);
    }
    PetscReal umin = PETSC_MAX_REAL, umax = 0; // the pivots' spread: a cheap conditioning check (the step length is checked below)
    for (PetscInt c = 0; c < nC; ++c) {
      umin = std::min(umin, std::abs(M[c + (size_t)c * nC]));
      umax = std::max(umax, std::abs(M[c + (size_t)c * nC]));
    }
    info->pivotRatio = umax > 0 ? umin / umax : 0;
    if (!(info->pivotRatio > 1e-12)) {
      info->reason = "I - J ill-conditioned";
      PetscFunctionReturn(0);
    }
    LAPACKgetrs_("N", &n, &one, M.data(), &n, piv.data(), z.data(), &n, &info2);
    if (info2) {
      info->reason = "I - J solve failed";
      PetscFunctionReturn(0);
    }
  }
  std::vector<PetscReal> dx(r);
  for (PetscInt c = 0; c < nC; ++c)
    for (PetscInt q = 0; q < nD; ++q) dx[q] += J[q + (size_t)c * nD] * z[c];
  PetscReal ndx = 0;
  bool      finite = true;
  for (PetscReal v : dx) {
    ndx += v * v;
    finite = finite && std::isfinite(v);
  }
  ndx         = std::sqrt(ndx);
  info->ratio = nr > 0 ? ndx / nr : 0;
  if (!finite) {
    info->reason = "non-finite step";
    PetscFunctionReturn(0);
  }
  if (info->ratio > maxRatio) {
    info->reason = "step too long";
    PetscFunctionReturn(0);
  }
  next->resize(nD);
  for (PetscInt q = 0; q < nD; ++q) (*next)[q] = in.x[q] + dx[q];
  info->accepted = true;
  info->reason   = "";
  PetscFunctionReturn(0);
}

} // namespace rbc
