// tests/test_closest_point.cpp: the binned closest-point search against brute force over all facets,
// on a circle polyline (2D segments) and a triangulated sphere patch (3D triangles); the candidate scan
// FindAmong (pruned by bounding circles and spheres) against the plain scan, bit for bit; and the facet
// Lagrange basis (partition of unity, nodal interpolation) for P1 and P2.
#include "rbcontact/contact.hpp"
#include <algorithm>
#include <cmath>
#include <random>

using namespace rbc;

static int failures = 0;
static void Check(bool ok, const char *what, double v)
{
  std::printf("  %-6s %-55s %.3e\n", ok ? "ok" : "FAIL", what, v);
  if (!ok) ++failures;
}

// FindAmong against a plain scan of DistToFacet2 over the same list (ties to the lower facet number): the same facet,
// the same nb barycentric coordinates and distance, bit for bit.
static bool SameAsPlainScan(const ClosestPoint &cp, const PetscReal p[], const std::vector<PetscInt> &cand, int nb)
{
  PetscInt  m, mref = -1;
  PetscReal b[3], d, bref[3] = {0, 0, 0}, best = PETSC_MAX_REAL;
  cp.FindAmong(p, cand.data(), (PetscInt)cand.size(), &m, b, &d);
  for (PetscInt j : cand) {
    PetscReal       bb[3];
    const PetscReal dd = cp.DistToFacet2(j, p, bb);
    if (dd < best || (dd == best && j < mref)) {
      best = dd;
      mref = j;
      for (int e = 0; e < nb; ++e) bref[e] = bb[e];
    }
  }
  bool same = m == mref && d == std::sqrt(best);
  for (int e = 0; e < nb; ++e) same = same && b[e] == bref[e];
  return same;
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  std::mt19937                           gen(5);
  std::uniform_real_distribution<double> U(-1.5, 1.5);
  // 2D: circle of radius 1 with 400 segments
  {
    std::vector<SurfaceFacet> f;
    const int                 n = 400;
    for (int i = 0; i < n; ++i) {
      SurfaceFacet F;
      F.nv = 2; F.nnodes = 2; F.nodeKind[0] = 0; F.nodeKind[1] = 1;
      const double a0 = 2 * M_PI * i / n, a1 = 2 * M_PI * (i + 1) / n;
      F.X[0] = std::cos(a0); F.X[1] = std::sin(a0); F.X[2] = std::cos(a1); F.X[3] = std::sin(a1);
      F.U[0] = 0.01 * std::sin(3 * a0); F.U[3] = 0.02 * std::cos(a1); // deformed
      f.push_back(F);
    }
    ClosestPoint cp;
    PetscCall(cp.Build(f, 2, true));
    double worst = 0;
    for (int k = 0; k < 2000; ++k) {
      const PetscReal p[2] = {U(gen), U(gen)};
      PetscInt        m;
      PetscReal       b[3], d;
      cp.Find(p, &m, b, &d);
      double best = 1e300;
      for (int j = 0; j < n; ++j) {
        const PetscReal *x = cp.Vertices(j);
        const double     t[2] = {x[2] - x[0], x[3] - x[1]}, tt = t[0] * t[0] + t[1] * t[1];
        double           s = ((p[0] - x[0]) * t[0] + (p[1] - x[1]) * t[1]) / tt;
        s                  = std::min(1.0, std::max(0.0, s));
        best               = std::min(best, std::hypot(x[0] + s * t[0] - p[0], x[1] + s * t[1] - p[1]));
      }
      worst = std::max(worst, std::abs(d - best));
    }
    Check(worst <= 1e-14, "2D: binned distance equals brute force (2000 points)", worst);
    // FindAmong (pruned by the segments' bounding circles after the first candidate) against a plain scan of
    // DistToFacet2 over candidate lists: the same facet and coordinates, bit for bit. Random points with random subsets
    // (in random order), and points radially outside a vertex with the lists of its neighbourhood: there both
    // segments of the vertex are at the same distance up to rounding (the ties the pruning must not decide)
    int mismatch = 0, lists = 0;
    for (int k = 0; k < 4000; ++k) {
      PetscReal             p[2];
      std::vector<PetscInt> cand;
      if (k < 2000) {
        p[0] = U(gen);
        p[1] = U(gen);
        for (PetscInt j = 0; j < n; ++j)
          if (U(gen) < (k % 2 ? -1.35 : 0.0)) cand.push_back(j);
        std::shuffle(cand.begin(), cand.end(), gen);
      } else {
        const PetscInt   v = k % n;
        const PetscReal *x = cp.Vertices(v); // its first vertex: shared with segment v - 1
        const double     s = 1 + 0.2 * (U(gen) + 1.5);
        p[0]               = s * x[0];
        p[1]               = s * x[1];
        for (PetscInt j = -4; j <= 4; ++j) cand.push_back(((v + j) % n + n) % n);
        std::shuffle(cand.begin(), cand.end(), gen);
      }
      if (cand.empty()) continue;
      ++lists;
      mismatch += !SameAsPlainScan(cp, p, cand, 2);
    }
    Check(mismatch == 0 && lists > 3000, "2D: FindAmong (bounding-circle pruning) equals the plain scan on 4000 candidate lists (mismatches)", mismatch);
  }
  // 2D, the bound where it is tight: p on the line of segment A beyond its end (|p - c_A| = d_A + r_A exactly), and
  // first in the list a decoy B at the relative distance 1 + eps of d_A (eps 1e-13..1e-3). A must be visited and win:
  // a circle even 1e-10 too small would skip it for the smallest eps
  {
    std::vector<SurfaceFacet> f;
    std::vector<PetscReal>    pts;
    std::uniform_real_distribution<double> V(0, 1);
    for (int k = 0; k < 1000; ++k) {
      const double th = 2 * M_PI * V(gen), L = 0.5 + 1.5 * V(gen), s = 0.01 + V(gen), eps = std::pow(10.0, -3 - 10 * V(gen));
      const double u[2] = {std::cos(th), std::sin(th)}, w[2] = {-u[1], u[0]}, a0[2] = {U(gen), U(gen)};
      const double p[2] = {a0[0] + (L + s) * u[0], a0[1] + (L + s) * u[1]}, o = s * (1 + eps);
      SurfaceFacet A, B;
      A.nv = B.nv = 2; A.nnodes = B.nnodes = 2;
      A.nodeKind[0] = B.nodeKind[0] = 0; A.nodeKind[1] = B.nodeKind[1] = 1;
      A.X[0] = a0[0]; A.X[1] = a0[1]; A.X[2] = a0[0] + L * u[0]; A.X[3] = a0[1] + L * u[1];
      B.X[0] = p[0] + o * w[0] - u[0]; B.X[1] = p[1] + o * w[1] - u[1]; B.X[2] = p[0] + o * w[0] + u[0]; B.X[3] = p[1] + o * w[1] + u[1];
      f.push_back(A);
      f.push_back(B);
      pts.push_back(p[0]);
      pts.push_back(p[1]);
    }
    ClosestPoint cp;
    cp.SetVertices(f, 2, false);
    int wrong = 0;
    for (int k = 0; k < 1000; ++k) wrong += !SameAsPlainScan(cp, &pts[2 * k], {2 * k + 1, 2 * k}, 2); // the decoy first
    Check(wrong == 0, "2D: FindAmong visits the segment whose circle bound is tight (1000 decoys at 1 + 1e-13..1e-3)", wrong);
  }
  // 3D: triangulated patch z = 0.2 sin(x) cos(y) on [-1,1]^2
  {
    std::vector<SurfaceFacet> f;
    const int                 n = 20;
    auto                      z = [](double x, double y) { return 0.2 * std::sin(x) * std::cos(y); };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double x0 = -1 + 2.0 * i / n, x1 = -1 + 2.0 * (i + 1) / n, y0 = -1 + 2.0 * j / n, y1 = -1 + 2.0 * (j + 1) / n;
        const double tri[2][9] = {{x0, y0, z(x0, y0), x1, y0, z(x1, y0), x1, y1, z(x1, y1)}, {x0, y0, z(x0, y0), x1, y1, z(x1, y1), x0, y1, z(x0, y1)}};
        for (auto &t : tri) {
          SurfaceFacet F;
          F.nv = 3; F.nnodes = 3;
          for (int k = 0; k < 3; ++k) F.nodeKind[k] = k;
          for (int k = 0; k < 9; ++k) F.X[k] = t[k];
          f.push_back(F);
        }
      }
    ClosestPoint cp;
    PetscCall(cp.Build(f, 3, false));
    double worst = 0;
    for (int k = 0; k < 500; ++k) {
      const PetscReal p[3] = {U(gen), U(gen), 0.5 * U(gen)};
      PetscInt        m;
      PetscReal       b[3], d;
      cp.Find(p, &m, b, &d);
      // brute force on a fine barycentric grid of every triangle (upper bound on the distance)
      double best = 1e300;
      for (PetscInt j = 0; j < cp.NumFacets(); ++j) {
        const PetscReal *x = cp.Vertices(j);
        for (int a = 0; a <= 40; ++a)
          for (int c = 0; c <= 40 - a; ++c) {
            const double b1 = a / 40.0, b2 = c / 40.0, b0 = 1 - b1 - b2;
            double       q2 = 0;
            for (int e = 0; e < 3; ++e) q2 += std::pow(b0 * x[e] + b1 * x[3 + e] + b2 * x[6 + e] - p[e], 2);
            best = std::min(best, std::sqrt(q2));
          }
      }
      worst = std::max(worst, d - best); // d must not exceed any sampled distance
    }
    Check(worst <= 1e-14, "3D: binned distance <= every sampled facet distance", worst);
    // FindAmong (pruned by the candidates' bounding spheres in 3D) against a plain scan of DistToFacet2 over
    // random candidate subsets: the same facet and barycentric coordinates, bit for bit
    int mismatch = 0;
    for (int k = 0; k < 2000; ++k) {
      const PetscReal       p[3] = {U(gen), U(gen), 0.5 * U(gen)};
      std::vector<PetscInt> cand;
      for (PetscInt j = 0; j < cp.NumFacets(); ++j)
        if (U(gen) < (k % 2 ? 0.05 : 0.5)) cand.push_back(j);
      if (cand.empty()) continue;
      mismatch += !SameAsPlainScan(cp, p, cand, 3);
    }
    Check(mismatch == 0, "3D: FindAmong (bounding-sphere pruning) equals the plain scan on 2000 random candidate sets (mismatches)", mismatch);
  }
  // Facet basis: P2 segment nodes (v0, v1, edge) interpolate x^2 exactly; partition of unity.
  {
    SurfaceFacet F;
    F.nv = 2; F.nnodes = 3; F.nodeKind[0] = 3; F.nodeKind[1] = 0; F.nodeKind[2] = 1;
    double worst = 0;
    for (int k = 0; k <= 10; ++k) {
      const PetscReal t = k / 10.0, b[2] = {1 - t, t};
      PetscReal       N[6];
      FacetBasis(F, b, N);
      const double xs[3] = {0.5, 0.0, 1.0}; // node positions: edge midpoint, v0, v1
      double       s = 0, q = 0;
      for (int a = 0; a < 3; ++a) { s += N[a]; q += N[a] * xs[a] * xs[a]; }
      worst = std::max(worst, std::max(std::abs(s - 1), std::abs(q - t * t)));
    }
    Check(worst <= 1e-15, "P2 facet basis: partition of unity, exact on x^2", worst);
  }
  std::printf("%s (%d failure(s))\n", failures ? "closest_point test FAILED" : "closest_point test passed", failures);
  PetscCall(PetscFinalize());
  return failures ? 1 : 0;
}
