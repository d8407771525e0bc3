// tests/test_empirical_cubature.cpp: the empirical cubature (src/reduction/empirical_cubature.cpp)
// against independent references:
//  1. CubatureGram against the Gram matrix of the explicitly stacked fitting rows (each state's K^ and
//     g^ entries as functions of the weights, scaled to unit norm), on random data; CubatureActionGram
//     likewise against its rows (K^' lam_j and K^ v_j - g^ per training solution j, scaled per state),
//     and with the resultant-force rows F_s(lam_j) added.
//  2. Caratheodory/Tchakaloff: moments of degree 0..4 of a 60-point rule on [0, 1] are reproduced by a
//     nonnegative rule on at most 5 of its points; the sparse NNLS finds one (weights > 0, support <= 5,
//     residual <= 1e-9) and the moments it gives match the full rule's.
//  3. Random reduced terms (R = 4, N = 3, 12 states, Q = 80): weights >= 0, the final residual <= tol,
//     the residual recomputed from the fitted terms state by state equals the reported one, the history
//     decreases to it, and fewer points than Q are used; the incremental Cholesky factor gives the same fit; the hierarchical fit (4 groups, -ecsw_group_points):
//     every group within its tolerance, the residual against the exact terms over all points <= tol; the Gram
//     system on candidates (H_CC, b_C, c) against the explicit rows (1b).
//  4. The elimination after the fit (the default): on contact-like terms (vanishing beyond a moving edge), fewer points than the plain fit, a subset of the longer
//     fit it thins, weights > 0 and equal to the least-squares weights on the support (Gaussian elimination), the residual
//     recomputed from the terms <= tol; with no slack (eliminateFrom 1), the plain fit bit for bit or fewer points; the
//     same with the inverse formed afresh every 2 removals, and on the hierarchical fit's union (4 groups).
#include "rbcontact/empirical_cubature.hpp"
#include <petscblaslapack.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

using namespace rbc;

static int failures = 0;
static void Check(bool ok, const char *what, double val, double bound)
{
  PetscCallAbort(PETSC_COMM_WORLD, PetscPrintf(PETSC_COMM_WORLD, "  %-5s %-72s %.3e (bound %.1e)\n", ok ? "ok" : "FAIL", what, val, bound));
  if (!ok) ++failures;
}

// Fitted terms of state s with weights xi: K (R x N) and g (R), and the exact ones (xi = 1).
static void Terms(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt s, const std::vector<PetscReal> &xi, std::vector<PetscReal> *K, std::vector<PetscReal> *g)
{
  K->assign((size_t)R * N, 0.0);
  g->assign(R, 0.0);
  for (PetscInt r = 0; r < R; ++r)
    for (PetscInt p = 0; p < Q; ++p) {
      const PetscReal w = xi[p] * P[(size_t)r * Q + p];
      (*g)[r] += w * Sg[(size_t)s * Q + p];
      for (PetscInt n = 0; n < N; ++n) (*K)[(size_t)r * N + n] += w * Sk[((size_t)s * Q + p) * N + n];
    }
}

// max |G'G - H| / max |G'G| for the explicit fitting rows G (rows x Q, row-major) and a computed Gram H.
static PetscReal GramMismatch(const std::vector<PetscReal> &G, PetscInt Q, const std::vector<PetscReal> &H)
{
  const size_t rows = G.size() / Q;
  PetscReal    d = 0, sc = 0;
  for (PetscInt p = 0; p < Q; ++p)
    for (PetscInt q = 0; q < Q; ++q) {
      PetscReal h = 0;
      for (size_t i = 0; i < rows; ++i) h += G[i * Q + p] * G[i * Q + q];
      d  = std::max(d, std::abs(h - H[(size_t)p * Q + q]));
      sc = std::max(sc, std::abs(h));
    }
  return sc > 0 ? d / sc : d;
}

// (K' lam_j) (N) for K (R x N, row-major) and the training multipliers Lam (nt x R, row-major): the action fit's force rows.
static std::vector<PetscReal> ForceAction(const std::vector<PetscReal> &K, const std::vector<PetscReal> &Lam, PetscInt j, PetscInt R, PetscInt N)
{
  std::vector<PetscReal> f(N, 0.0);
  for (PetscInt n = 0; n < N; ++n)
    for (PetscInt r = 0; r < R; ++r) f[n] += K[(size_t)r * N + n] * Lam[(size_t)j * R + r];
  return f;
}

// State s's terms K, g at the single point p with unit weight (e: the weights, reset to e_p) and the force action
// K' lam_j of them: the coefficient of xi_p in the explicit rows
static std::vector<PetscReal> UnitPointForce(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt s, PetscInt p, const std::vector<PetscReal> &Lam, PetscInt j, std::vector<PetscReal> *e, std::vector<PetscReal> *K, std::vector<PetscReal> *g)
{
  std::fill(e->begin(), e->end(), 0.0);
  (*e)[p] = 1;
  Terms(P, R, Q, N, Sk, Sg, s, *e, K, g);
  return ForceAction(*K, Lam, j, R, N);
}

// x = S^{-1} b by Gaussian elimination with partial pivoting (S n x n, row-major, copied)
static std::vector<PetscReal> SolveDense(PetscInt n, std::vector<PetscReal> S, std::vector<PetscReal> b)
{
  for (PetscInt c = 0; c < n; ++c) {
    PetscInt piv = c;
    for (PetscInt r = c + 1; r < n; ++r)
      if (std::abs(S[(size_t)r * n + c]) > std::abs(S[(size_t)piv * n + c])) piv = r;
    for (PetscInt j = 0; j < n; ++j) std::swap(S[(size_t)c * n + j], S[(size_t)piv * n + j]);
    std::swap(b[c], b[piv]);
    for (PetscInt r = c + 1; r < n; ++r) {
      const PetscReal f = S[(size_t)r * n + c] / S[(size_t)c * n + c];
      for (PetscInt j = c; j < n; ++j) S[(size_t)r * n + j] -= f * S[(size_t)c * n + j];
      b[r] -= f * b[c];
    }
  }
  std::vector<PetscReal> x(n);
  for (PetscInt r = n - 1; r >= 0; --r) {
    PetscReal t = b[r];
    for (PetscInt j = r + 1; j < n; ++j) t -= S[(size_t)r * n + j] * x[j];
    x[r] = t / S[(size_t)r * n + r];
  }
  return x;
}

static PetscReal Norm2(const std::vector<PetscReal> &v)
{
  PetscReal s = 0;
  for (PetscReal x : v) s += x * x;
  return s;
}

// The terms fit's residual recomputed state by state from the fitted terms (weights xi) against the exact ones:
// sqrt(sum_s (|dK_s|^2 / |K_s|^2 + |dg_s|^2 / |g_s|^2) / (2 ms)).
static PetscReal TermsFitResidual(const std::vector<PetscReal> &P, PetscInt R, PetscInt Q, PetscInt N, const std::vector<PetscReal> &Sk, const std::vector<PetscReal> &Sg, PetscInt ms, const std::vector<PetscReal> &xi)
{
  std::vector<PetscReal> one(Q, 1.0), K, g, K0, g0;
  PetscReal              sum = 0;
  for (PetscInt s = 0; s < ms; ++s) {
    Terms(P, R, Q, N, Sk, Sg, s, xi, &K, &g);
    Terms(P, R, Q, N, Sk, Sg, s, one, &K0, &g0);
    std::vector<PetscReal> dK(K.size()), dg(g.size());
    for (size_t i = 0; i < K.size(); ++i) dK[i] = K[i] - K0[i];
    for (size_t i = 0; i < g.size(); ++i) dg[i] = g[i] - g0[i];
    sum += Norm2(dK) / Norm2(K0) + Norm2(dg) / Norm2(g0);
  }
  return std::sqrt(sum / (2 * ms));
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, "test_empirical_cubature"));
  std::mt19937_64                        gen(3);
  std::uniform_real_distribution<double> U(-1, 1);

  { // 1. Gram matrix against the explicit rows
    const PetscInt         R = 3, Q = 17, N = 2, ms = 4;
    std::vector<PetscReal> P((size_t)R * Q), Sk((size_t)ms * Q * N), Sg((size_t)ms * Q), H;
    for (auto &x : P) x = std::abs(U(gen));
    for (auto &x : Sk) x = U(gen);
    for (auto &x : Sg) x = U(gen);
    CubatureGram(P, R, Q, N, Sk, Sg, ms, &H);
    std::vector<PetscReal> G; // rows x Q, row-major
    std::vector<PetscReal> K, g, one(Q, 1.0);
    for (PetscInt s = 0; s < ms; ++s) {
      Terms(P, R, Q, N, Sk, Sg, s, one, &K, &g);
      const PetscReal sk = 1 / std::sqrt(Norm2(K)), sg = 1 / std::sqrt(Norm2(g));
      for (PetscInt r = 0; r < R; ++r) {
        for (PetscInt n = 0; n < N; ++n)
          for (PetscInt p = 0; p < Q; ++p) G.push_back(sk * P[(size_t)r * Q + p] * Sk[((size_t)s * Q + p) * N + n]);
        for (PetscInt p = 0; p < Q; ++p) G.push_back(sg * P[(size_t)r * Q + p] * Sg[(size_t)s * Q + p]);
      }
    }
    const PetscReal d = GramMismatch(G, Q, H);
    Check(d <= 1e-13, "CubatureGram = G'G of the explicit fitting rows (max |diff| / max |G'G|)", d, 1e-13);
    // the Hadamard product accumulated 2 columns at a time (17: a partial last block); by default one block holds
    // every column up to about 64 MB, so only the finest 3D level's Gram systems are split
    std::vector<PetscReal> H2;
    SetCubatureGramColumnBlock(2);
    CubatureGram(P, R, Q, N, Sk, Sg, ms, &H2);
    SetCubatureGramColumnBlock(0);
    const PetscReal d2 = GramMismatch(G, Q, H2);
    Check(d2 <= 1e-13, "CubatureGram, its products 2 columns at a time = G'G of the explicit rows", d2, 1e-13);
  }

  { // 1b. the action fit's Gram matrix against its explicit rows: per state s and training solution j,
    // (K_s(xi)' lam_j) / sqrt(sum_j |K_s' lam_j|^2) and (K_s(xi) v_j - g_s(xi)) / sqrt(sum_j |K_s v_j|^2 + |g_s|^2)
    const PetscInt         R = 3, Q = 17, N = 2, ms = 4, nt = 3;
    std::vector<PetscReal> P((size_t)R * Q), Sk((size_t)ms * Q * N), Sg((size_t)ms * Q), Lam((size_t)nt * R), Vs((size_t)nt * N), H;
    for (auto &x : P) x = std::abs(U(gen));
    for (auto &x : Sk) x = U(gen);
    for (auto &x : Sg) x = U(gen);
    for (auto &x : Lam) x = std::abs(U(gen));
    for (auto &x : Vs) x = U(gen);
    CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &H);
    // with the force term: w n2 per point (dim 2), F_s(lam_j)_d = sum_p (P' lam_j)(p) xi_p Sw_s(p, d)
    const PetscInt         dim = 2;
    std::vector<PetscReal> Sw((size_t)ms * Q * dim), HF;
    for (auto &x : Sw) x = U(gen);
    CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HF, Sw, dim);
    std::vector<PetscReal> GF; // the force rows alone, scaled per state
    for (PetscInt s = 0; s < ms; ++s) {
      std::vector<PetscReal> rows((size_t)nt * dim * Q);
      PetscReal              n3 = 0;
      for (PetscInt j = 0; j < nt; ++j)
        for (PetscInt d = 0; d < dim; ++d)
          for (PetscInt p = 0; p < Q; ++p) {
            PetscReal l = 0;
            for (PetscInt r = 0; r < R; ++r) l += Lam[(size_t)j * R + r] * P[(size_t)r * Q + p];
            rows[((size_t)j * dim + d) * Q + p] = l * Sw[((size_t)s * Q + p) * dim + d];
          }
      for (PetscInt k = 0; k < nt * dim; ++k) {
        PetscReal t = 0;
        for (PetscInt p = 0; p < Q; ++p) t += rows[(size_t)k * Q + p];
        n3 += t * t;
      }
      for (auto &x : rows) x /= std::sqrt(n3);
      GF.insert(GF.end(), rows.begin(), rows.end());
    }
    std::vector<PetscReal> G, K, g, one(Q, 1.0), e(Q);
    for (PetscInt s = 0; s < ms; ++s) {
      Terms(P, R, Q, N, Sk, Sg, s, one, &K, &g);
      PetscReal n1 = 0, n2 = 0;
      for (PetscInt j = 0; j < nt; ++j) {
        for (PetscReal t : ForceAction(K, Lam, j, R, N)) n1 += t * t;
        for (PetscInt r = 0; r < R; ++r) {
          PetscReal t = 0;
          for (PetscInt n = 0; n < N; ++n) t += K[(size_t)r * N + n] * Vs[(size_t)j * N + n];
          n2 += t * t + g[r] * g[r];
        }
      }
      // each row is linear in xi: its coefficient of xi_p from the terms with xi = e_p
      for (PetscInt j = 0; j < nt; ++j) {
        std::vector<PetscReal> rows1((size_t)N * Q), rows2((size_t)R * Q);
        for (PetscInt p = 0; p < Q; ++p) {
          const std::vector<PetscReal> f = UnitPointForce(P, R, Q, N, Sk, Sg, s, p, Lam, j, &e, &K, &g);
          for (PetscInt n = 0; n < N; ++n) rows1[(size_t)n * Q + p] = f[n] / std::sqrt(n1);
          for (PetscInt r = 0; r < R; ++r) {
            PetscReal t = -g[r];
            for (PetscInt n = 0; n < N; ++n) t += K[(size_t)r * N + n] * Vs[(size_t)j * N + n];
            rows2[(size_t)r * Q + p] = t / std::sqrt(n2);
          }
        }
        G.insert(G.end(), rows1.begin(), rows1.end());
        G.insert(G.end(), rows2.begin(), rows2.end());
      }
    }
    const PetscReal d = GramMismatch(G, Q, H);
    Check(d <= 1e-13, "CubatureActionGram = G'G of the explicit rows (K' lam_j, K v_j - g; max |diff| / max |G'G|)", d, 1e-13);
    std::vector<PetscReal> GG(G);
    GG.insert(GG.end(), GF.begin(), GF.end());
    const PetscReal dF = GramMismatch(GG, Q, HF);
    Check(dF <= 1e-13, "CubatureActionGram with the force rows (F(lam_j) per component) = G'G of the explicit rows", dF, 1e-13);
    // the states in blocks (2 blocks of 2 states): the same Gram matrix to rounding
    std::vector<PetscReal> HB;
    CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HB, Sw, dim, 2);
    const PetscReal dB = GramMismatch(GG, Q, HB);
    Check(ms > 2 && dB <= 1e-13, "CubatureActionGram with the states in blocks of 2 = G'G of the explicit rows", dB, 1e-13);
    // the Hadamard products 2 columns at a time (a partial last block), the states in blocks of 2
    std::vector<PetscReal> HK;
    SetCubatureGramColumnBlock(2);
    CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HK, Sw, dim, 2);
    SetCubatureGramColumnBlock(0);
    const PetscReal dK = GramMismatch(GG, Q, HK);
    Check(dK <= 1e-13, "CubatureActionGram, products 2 columns at a time, states in blocks of 2 = G'G of the explicit rows", dK, 1e-13);
    // the lambda fit (metric T_j, k_j x R: 2, 0 and 3 rows): the constraint rows T_j (K_s(e_p) v_j - g_s(e_p)) / sqrt(sum_j
    // |T_j K_s v_j|^2 + |T_j g_s|^2) in place of the plain ones; with the force rows; kappa_s v_j from the blocks and
    // from a kappaTimes callback
    {
      CubatureLambdaMetric metric;
      const PetscInt       ks[] = {2, 0, 3};
      for (PetscInt j = 0; j < nt; ++j) {
        metric.T.emplace_back((size_t)ks[j] * R);
        for (auto &x : metric.T.back()) x = U(gen);
      }
      std::vector<PetscReal> GL, GLF, HL, HL2, HL3;
      const PetscInt         rg = 2; // the forces' part: a random factor Fg (N x rg), rows Fg' K_s(e_p)' lam_j / sqrt(n2)
      std::vector<PetscReal> Fg((size_t)N * rg);
      for (auto &x : Fg) x = U(gen);
      for (PetscInt s = 0; s < ms; ++s) {
        Terms(P, R, Q, N, Sk, Sg, s, one, &K, &g);
        PetscReal n1 = 0, n2 = 0;
        for (PetscInt j = 0; j < nt; ++j) {
          for (PetscReal t : ForceAction(K, Lam, j, R, N)) n1 += t * t;
          const std::vector<PetscReal> &T = metric.T[j];
          for (PetscInt i = 0; i < ks[j]; ++i) {
            PetscReal a = 0, b = 0;
            for (PetscInt r = 0; r < R; ++r) {
              PetscReal kv = 0;
              for (PetscInt n = 0; n < N; ++n) kv += K[(size_t)r * N + n] * Vs[(size_t)j * N + n];
              a += T[(size_t)i * R + r] * kv;
              b += T[(size_t)i * R + r] * g[r];
            }
            n2 += a * a + b * b;
          }
        }
        for (PetscInt j = 0; j < nt; ++j) {
          std::vector<PetscReal> rows1((size_t)N * Q), rows2((size_t)ks[j] * Q), rows3((size_t)rg * Q, 0.0);
          for (PetscInt p = 0; p < Q; ++p) {
            const std::vector<PetscReal> f = UnitPointForce(P, R, Q, N, Sk, Sg, s, p, Lam, j, &e, &K, &g);
            for (PetscInt n = 0; n < N; ++n) rows1[(size_t)n * Q + p] = f[n] / std::sqrt(n1);
            for (PetscInt c = 0; c < rg; ++c)
              for (PetscInt n = 0; n < N; ++n) rows3[(size_t)c * Q + p] += Fg[(size_t)n * rg + c] * f[n] / std::sqrt(n2);
            for (PetscInt i = 0; i < ks[j]; ++i) {
              PetscReal t = 0;
              for (PetscInt r = 0; r < R; ++r) {
                PetscReal c = -g[r];
                for (PetscInt n = 0; n < N; ++n) c += K[(size_t)r * N + n] * Vs[(size_t)j * N + n];
                t += metric.T[j][(size_t)i * R + r] * c;
              }
              rows2[(size_t)i * Q + p] = t / std::sqrt(n2);
            }
          }
          GL.insert(GL.end(), rows1.begin(), rows1.end());
          GL.insert(GL.end(), rows2.begin(), rows2.end());
          GLF.insert(GLF.end(), rows3.begin(), rows3.end());
        }
      }
      GL.insert(GL.end(), GF.begin(), GF.end());
      GLF.insert(GLF.begin(), GL.begin(), GL.end());
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HL, Sw, dim, 2, nullptr, nullptr, &metric);
      const PetscReal dL = GramMismatch(GL, Q, HL);
      Check(dL <= 1e-13, "CubatureActionGram with the lambda metric (T_j (K v_j - g) rows, force rows, blocks of 2) = G'G of the explicit rows", dL, 1e-13);
      metric.kappaTimes = [&](PetscInt s, PetscInt j, PetscReal *y) {
        for (PetscInt p = 0; p < Q; ++p) {
          y[p] = 0;
          for (PetscInt n = 0; n < N; ++n) y[p] += Sk[((size_t)s * Q + p) * N + n] * Vs[(size_t)j * N + n];
        }
      };
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HL2, Sw, dim, 0, nullptr, nullptr, &metric);
      const PetscReal dL2 = GramMismatch(GL, Q, HL2);
      Check(dL2 <= 1e-13, "CubatureActionGram with the lambda metric, kappa_s v_j by the callback = G'G of the explicit rows", dL2, 1e-13);
      metric.forceFactor = Fg;
      metric.forceRank   = rg;
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HL3, Sw, dim, 2, nullptr, nullptr, &metric);
      const PetscReal dL3 = GramMismatch(GLF, Q, HL3);
      Check(dL3 <= 1e-13, "CubatureActionGram with the lambda metric and its force factor (rows Fg' K_s(e_p)' lam_j in the constraint scaling) = G'G of the explicit rows", dL3, 1e-13);
    }
    // CubatureLambdaWeights against the reduced saddle point solved directly: for a change dr of the constraint values,
    // [A K_F'; K_F 0] [x; y] = [0; dr_F] (Gaussian elimination with partial pivoting) gives the multiplier change y, and
    // |T dr|^2 must equal y' M_F y (free set F: the positive coefficients, 3 of 4)
    {
      const PetscInt         Rw = 4, Nw = 5;
      std::vector<PetscReal> A((size_t)Nw * Nw, 0.0), B((size_t)Nw * Nw), Kw((size_t)Rw * Nw), lam = {0.3, 0.0, 1.2, 0.7}, M((size_t)Rw * Rw, 0.0), C((size_t)Rw * Rw), T;
      for (auto &x : B) x = U(gen);
      for (PetscInt i = 0; i < Nw; ++i)
        for (PetscInt j = 0; j < Nw; ++j) {
          for (PetscInt k = 0; k < Nw; ++k) A[i + (size_t)Nw * j] += B[i + (size_t)Nw * k] * B[j + (size_t)Nw * k];
          if (i == j) A[i + (size_t)Nw * j] += 0.5;
        }
      for (auto &x : Kw) x = U(gen);
      for (auto &x : C) x = U(gen);
      for (PetscInt i = 0; i < Rw; ++i)
        for (PetscInt j = 0; j < Rw; ++j) {
          for (PetscInt k = 0; k < Rw; ++k) M[(size_t)i * Rw + j] += C[(size_t)i * Rw + k] * C[(size_t)j * Rw + k];
          if (i == j) M[(size_t)i * Rw + j] += 0.1;
        }
      const PetscInt k = CubatureLambdaWeights(Rw, Nw, A.data(), Kw.data(), lam.data(), M, &T);
      const std::vector<PetscInt> F = {0, 2, 3};
      PetscReal                   worst = 0;
      for (PetscInt trial = 0; trial < 3; ++trial) {
        std::vector<PetscReal> dr(Rw);
        for (auto &x : dr) x = U(gen);
        const PetscInt         n = Nw + 3;
        std::vector<PetscReal> Sd((size_t)n * n, 0.0), rhs(n, 0.0); // row-major saddle matrix
        for (PetscInt i = 0; i < Nw; ++i)
          for (PetscInt j = 0; j < Nw; ++j) Sd[(size_t)i * n + j] = A[i + (size_t)Nw * j];
        for (PetscInt c = 0; c < 3; ++c) {
          for (PetscInt i = 0; i < Nw; ++i) Sd[(size_t)i * n + Nw + c] = Sd[(size_t)(Nw + c) * n + i] = Kw[F[c] + (size_t)Rw * i];
          rhs[Nw + c] = dr[F[c]];
        }
        const std::vector<PetscReal> x = SolveDense(n, Sd, rhs);
        PetscReal yMy = 0, Tdr = 0;
        for (PetscInt a = 0; a < 3; ++a)
          for (PetscInt b = 0; b < 3; ++b) yMy += x[Nw + a] * M[(size_t)F[a] * Rw + F[b]] * x[Nw + b];
        for (PetscInt i = 0; i < k; ++i) {
          PetscReal t = 0;
          for (PetscInt r = 0; r < Rw; ++r) t += T[(size_t)i * Rw + r] * dr[r];
          Tdr += t * t;
        }
        worst = std::max(worst, std::abs(Tdr - yMy) / yMy);
      }
      // C against the same saddle point with a change df of the forces: [A K_F'; K_F 0] [x; y] = [df; 0] gives
      // y = S_F^{-1} K_F A^{-1} df, and |C df|^2 must equal y' M_F y; CubatureLambdaForceFactor: Fg Fg' = (C'C + C'C) / 2
      // (a second, empty block not counted)
      std::vector<PetscReal> Cw, Fgw;
      (void)CubatureLambdaWeights(Rw, Nw, A.data(), Kw.data(), lam.data(), M, &T, &Cw);
      PetscReal worstC = 0;
      for (PetscInt trial = 0; trial < 3; ++trial) {
        std::vector<PetscReal> df(Nw);
        for (auto &x : df) x = U(gen);
        const PetscInt         n = Nw + 3;
        std::vector<PetscReal> Sd((size_t)n * n, 0.0), rhs(n, 0.0);
        for (PetscInt i = 0; i < Nw; ++i) {
          for (PetscInt j = 0; j < Nw; ++j) Sd[(size_t)i * n + j] = A[i + (size_t)Nw * j];
          rhs[i] = df[i];
        }
        for (PetscInt c = 0; c < 3; ++c)
          for (PetscInt i = 0; i < Nw; ++i) Sd[(size_t)i * n + Nw + c] = Sd[(size_t)(Nw + c) * n + i] = Kw[F[c] + (size_t)Rw * i];
        const std::vector<PetscReal> x = SolveDense(n, Sd, rhs);
        PetscReal                    yMy = 0, Cdf = 0;
        for (PetscInt a = 0; a < 3; ++a)
          for (PetscInt b = 0; b < 3; ++b) yMy += x[Nw + a] * M[(size_t)F[a] * Rw + F[b]] * x[Nw + b];
        for (PetscInt i = 0; i < 3; ++i) {
          PetscReal t = 0;
          for (PetscInt m = 0; m < Nw; ++m) t += Cw[(size_t)i * Nw + m] * df[m];
          Cdf += t * t;
        }
        worstC = std::max(worstC, std::abs(Cdf - yMy) / yMy);
      }
      Check(Cw.size() == (size_t)3 * Nw && worstC <= 1e-10, "CubatureLambdaWeights: |C df|^2 = y' M_F y of the saddle point's multiplier change under a force change (max rel diff, 3 trials)", worstC, 1e-10);
      const PetscInt rgw = CubatureLambdaForceFactor(Nw, {Cw, {}, Cw}, &Fgw);
      PetscReal      dG = 0, gmax = 0;
      for (PetscInt a = 0; a < Nw; ++a)
        for (PetscInt b = 0; b < Nw; ++b) {
          PetscReal g = 0, ff = 0;
          for (PetscInt i = 0; i < 3; ++i) g += Cw[(size_t)i * Nw + a] * Cw[(size_t)i * Nw + b];
          for (PetscInt c = 0; c < rgw; ++c) ff += Fgw[(size_t)a * rgw + c] * Fgw[(size_t)b * rgw + c];
          dG   = std::max(dG, std::abs(g - ff));
          gmax = std::max(gmax, std::abs(g));
        }
      Check(rgw == 3 && dG <= 1e-12 * gmax, "CubatureLambdaForceFactor: Fg Fg' = the mean of C'C, rank 3 (max abs diff / max entry)", dG / gmax, 1e-12);
      PetscReal inactive = 0; // the inactive row's column of T is zero
      for (PetscInt i = 0; i < k; ++i) inactive = std::max(inactive, std::abs(T[(size_t)i * Rw + 1]));
      Check(k == 3 && worst <= 1e-10 && inactive == 0, "CubatureLambdaWeights: |T dr|^2 = y' M_F y of the saddle point's multiplier change (max rel diff, 3 trials)", worst, 1e-10);
      std::vector<PetscReal> zero(Rw, 0.0);
      const PetscInt k0 = CubatureLambdaWeights(Rw, Nw, A.data(), Kw.data(), zero.data(), M, &T);
      Check(k0 == 0 && T.empty(), "CubatureLambdaWeights: no contact, no rows (T's size)", (double)T.size(), 0);
    }
    // on candidate points C (every third point): H_CC, (H 1)_C and 1'H1 of the explicit rows over every point,
    // with the states in one block and in blocks of 2, and (cols 2) the products 2 columns at a time (6 candidates)
    CubatureCandidates cand;
    for (PetscInt p = 1; p < Q; p += 3) cand.points.push_back(p);
    for (PetscInt blk : {0, 2, -2}) {
      const bool cols2 = blk < 0;
      blk              = std::abs(blk);
      std::vector<PetscReal> HC;
      SetCubatureGramColumnBlock(cols2 ? 2 : 0);
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HC, Sw, dim, blk, &cand);
      SetCubatureGramColumnBlock(0);
      PetscReal d = 0, sc = 0, db = 0, sb = 0, c = 0;
      const size_t rows = GG.size() / Q, nc = cand.points.size();
      std::vector<PetscReal> G1(rows, 0.0);
      for (size_t i = 0; i < rows; ++i)
        for (PetscInt p = 0; p < Q; ++p) G1[i] += GG[i * Q + p];
      for (PetscReal t : G1) c += t * t;
      for (size_t a = 0; a < nc; ++a) {
        PetscReal b = 0;
        for (size_t i = 0; i < rows; ++i) b += GG[i * Q + cand.points[a]] * G1[i];
        db = std::max(db, std::abs(b - cand.b[a]));
        sb = std::max(sb, std::abs(b));
        for (size_t k = 0; k < nc; ++k) {
          PetscReal h = 0;
          for (size_t i = 0; i < rows; ++i) h += GG[i * Q + cand.points[a]] * GG[i * Q + cand.points[k]];
          d  = std::max(d, std::abs(h - HC[a * nc + k]));
          sc = std::max(sc, std::abs(h));
        }
      }
      Check(HC.size() == nc * nc && d <= 1e-13 * sc, cols2 ? "candidates, blocks of 2, products 2 columns at a time: H_CC = (G'G)_CC" : blk ? "candidates, blocks of 2: H_CC = (G'G)_CC (max |diff| / max)" : "candidates: H_CC = (G'G)_CC of the explicit rows (max |diff| / max)", d / sc, 1e-13);
      if (cols2) continue; // (the rest as with blocks of 2)
      Check(db <= 1e-13 * sb, blk ? "candidates, blocks of 2: b_C = (G'G 1)_C over every point" : "candidates: b_C = (G'G 1)_C over every point (max |diff| / max)", db / sb, 1e-13);
      Check(std::abs(c - cand.c) <= 1e-13 * c, "candidates: c = |G 1|^2 over every point (rel diff)", std::abs(c - cand.c) / c, 1e-13);
      // the per-state scalings formed by a first call and reused by a second: the same Gram system bit for bit
      CubatureScalings   sc2;
      CubatureCandidates c1 = cand, c2 = cand;
      std::vector<PetscReal> H1, H2;
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &H1, Sw, dim, blk, &c1, &sc2);
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &H2, Sw, dim, blk, &c2, &sc2);
      const bool sameCached = sc2.s1.size() == (size_t)ms && H1 == HC && H2 == HC && c1.b == cand.b && c2.b == cand.b && c2.c == cand.c;
      Check(sameCached, blk ? "scalings cached, blocks of 2: H_CC, b_C, c bit for bit those computed afresh" : "scalings cached: H_CC, b_C, c bit for bit those computed afresh", sameCached ? 0.0 : 1.0, 0.0);
      // the target only (the hierarchical fit's first pass): no Gram matrix, c as above, cOwn = |G_C 1_C|^2 of the
      // candidates' own terms
      CubatureCandidates own = cand;
      own.targetOnly         = true;
      std::vector<PetscReal> HO;
      CubatureActionGram(P, R, Q, N, Sk, Sg, ms, Lam, Vs, nt, &HO, Sw, dim, blk, &own);
      std::vector<PetscReal> GC(rows, 0.0);
      PetscReal              co = 0;
      for (size_t i = 0; i < rows; ++i)
        for (PetscInt p : cand.points) GC[i] += GG[i * Q + p];
      for (PetscReal t : GC) co += t * t;
      Check(HO.empty() && own.b.empty() && std::abs(c - own.c) <= 1e-13 * c && std::abs(co - own.cOwn) <= 1e-13 * co,
            blk ? "target only, blocks of 2: c, cOwn = |G_C 1_C|^2 of the explicit rows, no Gram matrix (rel diff)" : "target only: c = |G 1|^2, cOwn = |G_C 1_C|^2 of the explicit rows, no Gram matrix (rel diff)",
            std::max(std::abs(c - own.c) / c, std::abs(co - own.cOwn) / co), 1e-13);
    }
  }

  { // 2. moments 0..4 of a 60-point rule: a nonnegative rule on <= 5 of its points
    const PetscInt         Q = 60, N = 4, R = 1;
    std::vector<PetscReal> P(Q), Sk((size_t)Q * N), Sg(Q), H;
    for (PetscInt p = 0; p < Q; ++p) {
      const PetscReal x = (p + 0.5) / Q;
      P[p] = 1.0 / Q; // midpoint rule
      for (PetscInt n = 0; n < N; ++n) Sk[(size_t)p * N + n] = std::pow(x, n);
      Sg[p] = std::pow(x, 4);
    }
    CubatureGram(P, R, Q, N, Sk, Sg, 1, &H);
    CubatureOptions opt;
    opt.tol       = 1e-9;
    opt.eliminate = false; // Lawson-Hanson's own result (the elimination: 4.)
    CubatureResult res;
    PetscCall(EmpiricalCubature(H, Q, opt, &res));
    PetscReal wmin = PETSC_MAX_REAL;
    for (PetscReal w : res.weights) wmin = std::min(wmin, w);
    Check(res.residual <= 1e-9, "moments 0..4: relative residual", res.residual, 1e-9);
    Check(res.points.size() <= 5 && !res.points.empty(), "moments 0..4: number of points (Caratheodory: <= 5)", (double)res.points.size(), 5);
    Check(wmin > 0, "moments 0..4: every weight > 0 (min weight)", wmin, 0);
    PetscReal merr = 0;
    for (PetscInt n = 0; n <= 4; ++n) {
      PetscReal full = 0, cub = 0;
      for (PetscInt p = 0; p < Q; ++p) full += P[p] * std::pow((p + 0.5) / Q, n);
      for (size_t j = 0; j < res.points.size(); ++j) cub += res.weights[j] * P[res.points[j]] * std::pow((res.points[j] + 0.5) / Q, n);
      merr = std::max(merr, std::abs(cub - full) / full);
    }
    Check(merr <= 1e-8, "moments 0..4: max relative moment error of the sparse rule", merr, 1e-8);
  }

  { // 3. random reduced terms: the reported fit equals the fit recomputed state by state
    const PetscInt         R = 4, N = 3, ms = 12, Q = 80;
    std::vector<PetscReal> P((size_t)R * Q), Sk((size_t)ms * Q * N), Sg((size_t)ms * Q), H;
    for (PetscInt r = 0; r < R; ++r) // smooth nonnegative "dual vectors" times hats
      for (PetscInt p = 0; p < Q; ++p) P[(size_t)r * Q + p] = std::exp(-PetscSqr((p / (PetscReal)Q - 0.25 * r - 0.1) / 0.2));
    for (PetscInt s = 0; s < ms; ++s) // smooth state-dependent kernels
      for (PetscInt p = 0; p < Q; ++p) {
        const PetscReal x = p / (PetscReal)Q, a = 1 + 0.1 * s;
        for (PetscInt n = 0; n < N; ++n) Sk[((size_t)s * Q + p) * N + n] = std::sin(a * (n + 1) * x) + 0.1 * n;
        Sg[(size_t)s * Q + p] = std::cos(a * x) - 0.5 * x * x;
      }
    CubatureGram(P, R, Q, N, Sk, Sg, ms, &H);
    CubatureOptions opt;
    opt.tol       = 1e-5;
    opt.eliminate = false; // Lawson-Hanson's own result (the elimination: 4.)
    CubatureResult res;
    PetscCall(EmpiricalCubature(H, Q, opt, &res));
    std::vector<PetscReal> xi(Q, 0.0);
    PetscReal              wmin = PETSC_MAX_REAL;
    for (size_t j = 0; j < res.points.size(); ++j) {
      xi[res.points[j]] = res.weights[j];
      wmin              = std::min(wmin, res.weights[j]);
    }
    const PetscReal rec = TermsFitResidual(P, R, Q, N, Sk, Sg, ms, xi);
    Check(wmin > 0, "random terms: every weight > 0 (min weight)", wmin, 0);
    Check(res.residual <= opt.tol, "random terms: relative residual <= tol", res.residual, opt.tol);
    Check(std::abs(rec - res.residual) <= 1e-6 * opt.tol + 1e-3 * res.residual, "random terms: residual recomputed from the fitted terms (|diff|)", std::abs(rec - res.residual), 1e-3 * res.residual);
    Check((PetscInt)res.points.size() < Q, "random terms: points used (< Q)", (double)res.points.size(), Q);
    Check(res.history.back() == res.residual && res.history.front() == 1.0, "random terms: history from 1 to the final residual (last - residual)", res.history.back() - res.residual, 0);

    // the incremental Cholesky factor (the hierarchical fit's): the same points, weights to rounding
    CubatureOptions oi = opt;
    oi.incremental     = true;
    CubatureResult ri;
    PetscCall(EmpiricalCubature(H, Q, oi, &ri));
    PetscReal dw = ri.points == res.points ? 0 : 1;
    for (size_t j = 0; dw < 1 && j < ri.weights.size(); ++j) dw = std::max(dw, std::abs(ri.weights[j] - res.weights[j]) / res.weights[j]);
    // rounding bound: 10 cond(H(S, S)) eps (the two factorizations differ in the order of their operations)
    PetscReal bound = 1;
    {
      const PetscInt         k = (PetscInt)res.points.size();
      std::vector<PetscReal> A((size_t)k * k), w(k), work(8 * k + 8);
      for (PetscInt i = 0; i < k; ++i)
        for (PetscInt j = 0; j < k; ++j) A[i + (size_t)k * j] = H[(size_t)res.points[i] * Q + res.points[j]];
      PetscBLASInt n = (PetscBLASInt)k, lw = (PetscBLASInt)work.size(), info = 0;
      LAPACKsyev_("N", "L", &n, A.data(), &n, w.data(), work.data(), &lw, &info);
      if (info == 0 && w[0] > 0) bound = 10 * (w[k - 1] / w[0]) * PETSC_MACHINE_EPSILON;
    }
    // the residuals recomputed from the fitted terms (the reported ones come from x'Hx - 2 b'x + c, whose cancellation at
    // a residual of 2e-6 is about 1e-5 relative: the two fits' differ by 1.6e-5): equal to 1e-6
    std::vector<PetscReal> xr(Q, 0.0);
    for (size_t j = 0; j < ri.points.size(); ++j) xr[ri.points[j]] = ri.weights[j];
    const PetscReal reci = TermsFitResidual(P, R, Q, N, Sk, Sg, ms, xr);
    Check(dw <= bound && ri.residual <= opt.tol && std::abs(reci - rec) <= 1e-6 * rec, "incremental Cholesky: the same points, weights within 10 cond(H_SS) eps (max rel diff), the same residual", dw, bound);
    // the fit above removes a point (a Lawson-Hanson pass that removes one: more passes than points added), so the
    // factor's deletion of a row and column (a rank-one update of the rows below it) is part of what gave the same fit
    Check(ri.iterations > (PetscInt)ri.history.size() - 1, "incremental Cholesky: a point left the support (passes, points added)", (double)ri.iterations, (double)ri.history.size() - 1);

    // the hierarchical fit (4 groups of 20 points): points weights > 0, every group within its tolerance, and the
    // reported residual <= tol is the error against the exact terms over all 80 points (recomputed state by state)
    CubatureOptions oh = opt;
    oh.groupPoints     = 20;
    CubatureResult    rc;
    CubatureHierarchy hi;
    PetscCall(HierarchicalCubature(PETSC_COMM_SELF, Q, oh, [&](CubatureCandidates *c, std::vector<PetscReal> *Hc) { CubatureGram(P, R, Q, N, Sk, Sg, ms, Hc, c); }, &rc, &hi));
    std::vector<PetscReal> xc(Q, 0.0);
    bool                   pos = !rc.points.empty(), groupsOk = hi.groups == 4 && hi.groupResiduals.size() == 4 && hi.groupTol > 0 && hi.groupTol <= oh.tol;
    for (size_t j = 0; j < rc.points.size(); ++j) {
      pos = pos && rc.weights[j] > 0 && rc.points[j] >= 0 && rc.points[j] < Q;
      xc[rc.points[j]] = rc.weights[j];
    }
    for (PetscReal r : hi.groupResiduals) groupsOk = groupsOk && r <= hi.groupTol;
    const PetscReal recc = TermsFitResidual(P, R, Q, N, Sk, Sg, ms, xc);
    Check(pos && (PetscInt)rc.points.size() <= hi.candidates, "hierarchical (4 groups of 20): weights > 0, points among the groups' union (points)", (double)rc.points.size(), (double)hi.candidates);
    Check(groupsOk, "hierarchical: every group within its tolerance (group tol)", hi.groupTol, oh.tol);
    Check(rc.residual <= opt.tol, "hierarchical: relative residual <= tol", rc.residual, opt.tol);
    Check(std::abs(recc - rc.residual) <= 1e-6 * opt.tol + 1e-3 * rc.residual, "hierarchical: residual recomputed against the exact terms over all 80 points (|diff|)", std::abs(recc - rc.residual), 1e-3 * rc.residual);
    CubatureResult r1;
    oh.groupPoints = 80; // one group: the plain fit
    PetscCall(HierarchicalCubature(PETSC_COMM_SELF, Q, oh, [&](CubatureCandidates *c, std::vector<PetscReal> *Hc) { CubatureGram(P, R, Q, N, Sk, Sg, ms, Hc, c); }, &r1, &hi));
    Check(hi.groups == 1 && r1.points == res.points && r1.weights == res.weights, "hierarchical with one group = the plain fit (groups)", (double)hi.groups, 1);
  }

  { // 4. the elimination (-ecsw_eliminate, the default): a fit to eliminateFrom x tol thinned back to tol. Against the plain
    // fit and independent references: fewer points, a subset of the fit it started from, every weight > 0 and the
    // least-squares weights on its support (H(S, S) w = (H 1)(S) by Gaussian elimination, not the library's Cholesky),
    // the residual recomputed from the fitted terms state by state <= tol.
    const PetscInt         R = 6, N = 4, ms = 20, Q = 240;
    std::vector<PetscReal> P((size_t)R * Q), Sk((size_t)ms * Q * N), Sg((size_t)ms * Q), H;
    for (PetscInt r = 0; r < R; ++r)
      for (PetscInt p = 0; p < Q; ++p) P[(size_t)r * Q + p] = std::exp(-PetscSqr((p / (PetscReal)Q - 0.18 * r - 0.05) / 0.12));
    for (PetscInt s = 0; s < ms; ++s)
      for (PetscInt p = 0; p < Q; ++p) {
        // contact-like: terms that vanish beyond a contact edge moving with the state (kinks the points must resolve)
        const PetscReal x = p / (PetscReal)Q, edge = 0.3 + 0.03 * s, act = x < edge ? 1.0 : 0.0;
        for (PetscInt n = 0; n < N; ++n) Sk[((size_t)s * Q + p) * N + n] = act * std::cos((n + 1) * x + 0.1 * s);
        Sg[(size_t)s * Q + p] = act * (edge - x) * (1 + x);
      }
    CubatureGram(P, R, Q, N, Sk, Sg, ms, &H);
    CubatureOptions opt;
    opt.tol       = 1e-4;
    opt.eliminate = false;
    CubatureResult res;
    PetscCall(EmpiricalCubature(H, Q, opt, &res));
    std::vector<PetscReal> b1(Q, 0.0); // H 1
    for (PetscInt p = 0; p < Q; ++p)
      for (PetscInt q = 0; q < Q; ++q) b1[p] += H[(size_t)p * Q + q];
    // max rel diff of r's weights from the least-squares weights on r's support, and the rounding bound 10 cond(H(S, S)) eps
    auto lsWeightsDiff = [&](const CubatureResult &r, PetscReal *bound) {
      const PetscInt         k = (PetscInt)r.points.size();
      std::vector<PetscReal> A((size_t)k * k), rhs(k), ev(k), work(8 * k + 8);
      for (PetscInt i = 0; i < k; ++i) {
        rhs[i] = b1[r.points[i]];
        for (PetscInt j = 0; j < k; ++j) A[(size_t)i * k + j] = H[(size_t)r.points[i] * Q + r.points[j]];
      }
      const std::vector<PetscReal> w = SolveDense(k, A, rhs);
      PetscReal                    d = 0;
      for (PetscInt i = 0; i < k; ++i) d = std::max(d, std::abs(w[i] - r.weights[i]) / std::abs(w[i]));
      PetscBLASInt n = (PetscBLASInt)k, lw = (PetscBLASInt)work.size(), info = 0;
      LAPACKsyev_("N", "L", &n, A.data(), &n, ev.data(), work.data(), &lw, &info);
      *bound = info == 0 && ev[0] > 0 ? 10 * (ev[k - 1] / ev[0]) * PETSC_MACHINE_EPSILON : 1;
      return d;
    };
    for (const PetscReal from : {0.5, 0.3}) {
      CubatureOptions oe = opt;
      oe.eliminate       = true;
      oe.eliminateFrom   = from;
      CubatureResult re;
      PetscCall(EmpiricalCubature(H, Q, oe, &re));
      // the longer fit it started from: the plain fit to from x tol
      CubatureOptions of = opt;
      of.tol             = from * opt.tol;
      CubatureResult rf;
      PetscCall(EmpiricalCubature(H, Q, of, &rf));
      std::vector<PetscReal> xe(Q, 0.0);
      bool                   pos = !re.points.empty(), subset = true;
      for (size_t j = 0; j < re.points.size(); ++j) {
        pos = pos && re.weights[j] > 0;
        xe[re.points[j]] = re.weights[j];
        subset = subset && std::find(rf.points.begin(), rf.points.end(), re.points[j]) != rf.points.end();
      }
      PetscReal       bound;
      const PetscReal rece = TermsFitResidual(P, R, Q, N, Sk, Sg, ms, xe), dls = lsWeightsDiff(re, &bound);
      char            what[160];
      std::snprintf(what, sizeof what, "elimination from %.1f tol: %zu -> %zu points (eliminated), the plain fit %zu", (double)from, rf.points.size(), re.points.size(), res.points.size());
      Check(re.eliminated > 0 && re.points.size() < res.points.size() && re.plainPoints == (PetscInt)res.points.size() && re.points.size() + re.eliminated == rf.points.size(), what, (double)re.eliminated, 1);
      Check(pos && subset, "elimination: every weight > 0, the points a subset of the fit it started from (points)", (double)re.points.size(), (double)rf.points.size());
      Check(dls <= bound, "elimination: the least-squares weights on the support (Gaussian elimination; max rel diff, bound 10 cond eps)", dls, bound);
      Check(rece <= opt.tol && std::abs(rece - re.residual) <= 1e-6 * opt.tol + 1e-3 * re.residual && re.history.back() == re.residual,
            "elimination: residual recomputed from the fitted terms <= tol (recomputed)", rece, opt.tol);
    }
    // no slack (the fit stopped at tol, eliminateFrom 1): the plain fit's result unless fewer points reach tol
    CubatureOptions o1 = opt;
    o1.eliminate       = true;
    o1.eliminateFrom   = 1;
    CubatureResult re1;
    PetscCall(EmpiricalCubature(H, Q, o1, &re1));
    const bool same = re1.points == res.points && re1.weights == res.weights && re1.history == res.history && re1.eliminated == 0;
    Check(same || (re1.points.size() < res.points.size() && re1.residual <= opt.tol), same ? "elimination from tol: nothing removed, the plain fit bit for bit (points)" : "elimination from tol: fewer points within tol (points)", (double)re1.points.size(), (double)res.points.size());

    // the inverse formed afresh after every 2 removals (the refresh path; by default after max(64, k / 8)): the same checks
    auto valid = [&](const CubatureResult &r, const char *what, PetscInt plain) {
      std::vector<PetscReal> xr(Q, 0.0);
      bool                   pos = !r.points.empty();
      for (size_t j = 0; j < r.points.size(); ++j) {
        pos = pos && r.weights[j] > 0 && r.points[j] >= 0 && r.points[j] < Q;
        xr[r.points[j]] = r.weights[j];
      }
      const PetscReal rr = TermsFitResidual(P, R, Q, N, Sk, Sg, ms, xr);
      Check(pos && r.eliminated > 0 && (PetscInt)r.points.size() < plain && rr <= opt.tol && r.history.back() == r.residual, what, rr, opt.tol);
    };
    SetCubatureEliminationRefresh(2);
    CubatureOptions o3 = opt;
    o3.eliminate       = true;
    o3.eliminateFrom   = 0.3;
    CubatureResult rr2;
    PetscCall(EmpiricalCubature(H, Q, o3, &rr2));
    SetCubatureEliminationRefresh(0);
    valid(rr2, "elimination, inverse afresh every 2 removals: weights > 0, fewer points than the plain fit, residual recomputed <= tol", (PetscInt)res.points.size());

    // the hierarchical fit (4 groups of 60 points): the union's fit thinned (on candidates: indices mapped back to all points)
    CubatureOptions oh = opt;
    oh.groupPoints     = 60;
    CubatureResult    rh, rhe;
    CubatureHierarchy hi;
    auto              gram = [&](CubatureCandidates *cc, std::vector<PetscReal> *Hc) { CubatureGram(P, R, Q, N, Sk, Sg, ms, Hc, cc); };
    PetscCall(HierarchicalCubature(PETSC_COMM_SELF, Q, oh, gram, &rh, &hi));
    oh.eliminate = true;
    PetscCall(HierarchicalCubature(PETSC_COMM_SELF, Q, oh, gram, &rhe, &hi));
    valid(rhe, "hierarchical (4 groups of 60) with the elimination: weights > 0, fewer points than without, residual over all points <= tol", (PetscInt)rh.points.size());
  }
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, failures ? "test_empirical_cubature FAILED (%d failure(s))\n" : "test_empirical_cubature passed\n", failures));
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
