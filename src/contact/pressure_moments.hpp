// src/contact/pressure_moments.hpp: the size of the contact zone from the pressure's moments, one definition for the
// FOM report (SummarizeContact: contact_halfwidth_moment) and the reduced model's online outputs (SurfaceOutputs), so
// that both compute the same numbers in the same order. 2D: the half-width 2 sqrt(m2/m0 - (m1/m0)^2) of the tangent
// coordinates s_i; 3D: the radius sqrt(5/2 (m2/m0 - |m1/m0|^2)) of the points q_i projected on the plane normal to the
// resultant. Both are Hertz's a for Hertz's pressure profile. Weights f_i = lambda_i int psi_i. Internal (not installed).
#pragma once
#include <algorithm>
#include <cmath>
#include <petscsys.h>

namespace rbc {

// 2D: the moments of the tangent coordinate s
struct PressureMoments2 {
  PetscReal m0 = 0, m1 = 0, m2 = 0;
  void      Add(PetscReal s, PetscReal f)
  {
    m0 += f;
    m1 += f * s;
    m2 += f * s * s;
  }
  // false (and *a unchanged) without a positive total
  bool HalfWidth(PetscReal *a) const
  {
    if (!(m0 > 0)) return false;
    *a = 2 * std::sqrt(std::max<PetscReal>(0.0, m2 / m0 - (m1 / m0) * (m1 / m0)));
    return true;
  }
};

// 3D: the moments of x projected on the plane normal to nh (a unit vector: the resultant's direction)
struct PressureMoments3 {
  PetscReal nh[3], m0 = 0, m1[3] = {0, 0, 0}, m2 = 0;
  explicit PressureMoments3(const PetscReal n[3]) : nh{n[0], n[1], n[2]} {}
  void Add(PetscReal x0, PetscReal x1, PetscReal x2, PetscReal f)
  {
    const PetscReal x[3] = {x0, x1, x2}, xn = x0 * nh[0] + x1 * nh[1] + x2 * nh[2];
    PetscReal       q2   = 0;
    for (PetscInt d = 0; d < 3; ++d) {
      const PetscReal q = x[d] - xn * nh[d];
      q2 += q * q;
      m1[d] += f * q;
    }
    m0 += f;
    m2 += f * q2;
  }
  // false (and *a unchanged) without a positive total
  bool Radius(PetscReal *a) const
  {
    if (!(m0 > 0)) return false;
    *a = std::sqrt(std::max<PetscReal>(0.0, 2.5 * (m2 / m0 - (m1[0] * m1[0] + m1[1] * m1[1] + m1[2] * m1[2]) / (m0 * m0))));
    return true;
  }
};

} // namespace rbc
