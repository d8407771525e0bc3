// src/contact/kacanov_loop.cpp: KacanovLoop, the fixed-point loop shared by the full-order and the reduced
// Kacanov iterations (options, relaxation, primal change, stopping rule, Anderson mixing, monitor, history).
#include "rbcontact/kacanov_loop.hpp"
#include "rbcontact/options_files.hpp"
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rbc {

PetscReal KacanovLoop::RelChange(PetscReal diff, PetscReal prev, PetscReal cur)
{
  if (prev > 0) return diff / prev;
  return cur == 0 ? 0.0 : std::numeric_limits<PetscReal>::infinity();
}

PetscErrorCode KacanovLoop::SetFromOptions(MPI_Comm comm, const std::string &prefix)
{
  const std::string p = "-" + prefix + "kacanov_";

  PetscFunctionBeginUser;
  prefix_ = prefix;
  // given without a value, PETSc kept the default without a word (the FOM's and the ROM's loops alike)
  PetscCall(CheckValuesGiven(comm, prefix + "kacanov_", {"max_it", "rtol_primal", "rtol_dual", "relaxation", "anderson"}));
  PetscOptionsBegin(comm, (prefix + "kacanov_").c_str(), "Kacanov iterations", "KacanovLoop");
  PetscCall(PetscOptionsInt("-max_it", "Maximum Kacanov iterations (1: the linearized model)", NULL, maxIt, &maxIt, NULL));
  PetscCall(PetscOptionsReal("-rtol_primal", "Relative change of the primal input to stop", NULL, rtolPrimal, &rtolPrimal, NULL));
  PetscCall(PetscOptionsReal("-rtol_dual", "Relative change of the multipliers to stop", NULL, rtolDual, &rtolDual, NULL));
  PetscCall(PetscOptionsReal("-relaxation", "Under-relaxation factor in (0, 1]", NULL, relaxation, &relaxation, NULL));
  PetscCall(PetscOptionsInt("-anderson", "Anderson mixing depth on the primal input (0: plain Kacanov)", NULL, anderson, &anderson, NULL));
  PetscCall(PetscOptionsBool("-monitor", "Print the changes and the active-set size per iteration", NULL, monitor, &monitor, NULL));
  PetscOptionsEnd();
  PetscCheck(maxIt >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "%smax_it %" PetscInt_FMT " must be >= 1", p.c_str(), maxIt);
  // (inf was accepted: one iterate, reported converged)
  PetscCheck(rtolPrimal > 0 && rtolDual > 0 && std::isfinite(rtolPrimal) && std::isfinite(rtolDual), comm, PETSC_ERR_ARG_OUTOFRANGE, "%srtol_primal (%g) and %srtol_dual (%g) must be finite numbers > 0", p.c_str(), (double)rtolPrimal, p.c_str(), (double)rtolDual);
  PetscCheck(relaxation > 0 && relaxation <= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "%srelaxation %g must lie in (0, 1]", p.c_str(), (double)relaxation);
  PetscCheck(anderson >= 0 && anderson <= 10, comm, PETSC_ERR_ARG_OUTOFRANGE, "%sanderson %" PetscInt_FMT " must lie in [0, 10] (0: plain Kacanov)", p.c_str(), anderson);
  PetscFunctionReturn(0);
}

void KacanovLoop::Begin(PetscInt n)
{
  history.du.clear();
  history.dl.clear();
  history.nactive.clear();
  n_ = n;
  if (anderson > 0 && n > 0) aa_.Setup(n, anderson);
}

PetscReal KacanovLoop::Relax(const PetscReal *x, PetscReal *g) const
{
  PetscReal nx = 0, ng = 0, nd = 0;
  for (PetscInt i = 0; i < n_; ++i) {
    const PetscReal d = g[i] - x[i]; // the residual, before the relaxation (its square does not underflow with it)
    g[i]              = x[i] + relaxation * d;
    nx += x[i] * x[i];
    ng += g[i] * g[i];
    nd += d * d;
  }
  return RelChange(std::sqrt(nd), std::sqrt(nx), std::sqrt(ng));
}

PetscErrorCode KacanovLoop::Record(MPI_Comm comm, PetscInt k, PetscReal du, PetscReal dl, PetscInt nactive, PetscInt R, const char *detail, bool *converged, bool dualIsChange)
{
  PetscFunctionBeginUser;
  history.du.push_back(du);
  history.dl.push_back(dl);
  history.nactive.push_back(nactive);
  if (monitor) PetscCall(PetscPrintf(comm, "  %3" PetscInt_FMT " %s |du|/|u| %9.3e |dlambda|/|lambda| %9.3e%s active %" PetscInt_FMT "/%" PetscInt_FMT "%s%s%s\n", k, label.c_str(), (double)du, (double)dl, dualIsChange ? "" : " (from the warm start)", nactive, R, detail ? " (" : "", detail ? detail : "", detail ? ")" : ""));
  *converged = maxIt == 1 || (du <= rtolPrimal && (!dualIsChange || dl <= rtolDual));
  PetscFunctionReturn(0);
}

bool KacanovLoop::Next(const PetscReal *x, const PetscReal *g, PetscReal *next)
{
  if (anderson > 0 && n_ > 0 && aa_.Mix(x, g, next) > 0) return true;
  std::copy(g, g + n_, next);
  return false;
}

PetscInt KacanovLoop::Cycle(PetscInt *from) const
{
  const auto &du = history.du, &dl = history.dl;
  const auto &na    = history.nactive;
  const size_t n     = du.size();
  auto         close = [](PetscReal a, PetscReal b) { return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)); };
  auto         same  = [&](size_t j, size_t p) { return close(du[j], du[j - p]) && close(dl[j], dl[j - p]) && na[j] == na[j - p]; };
  for (size_t p = 2; p <= 12 && 3 * p <= n; ++p) {
    bool cyc = true;
    for (size_t i = 0; i < 2 * p && cyc; ++i) cyc = same(n - 1 - i, p);
    if (!cyc) continue;
    size_t s = n - 2 * p; // the repeating stretch starts at s - p at the latest: walk back while the match holds
    while (s > p && same(s - 1, p)) --s;
    if (from) *from = (PetscInt)(s - p) + 1;
    return (PetscInt)p;
  }
  return 0;
}

std::string KacanovLoop::NotConverged(bool withHistory, const std::string &cause, bool relaxationHint) const
{
  const std::string  p = "-" + prefix_ + "kacanov_";
  std::ostringstream o;
  o << label << " iterations did not converge in " << maxIt << " iterations (" << p << "max_it; tolerances " << p << "rtol_primal " << rtolPrimal << ", " << p << "rtol_dual " << rtolDual;
  // (it said "try ...relaxation 0.5" with 0.5 in use)
  if (relaxationHint) {
    o << "; try " << p << "relaxation " << 0.5 * relaxation;
    if (relaxation < 1) o << " (" << relaxation << " in use)";
  }
  o << ")";
  if (!history.du.empty()) o << "; last changes du " << history.du.back() << ", dlambda " << history.dl.back();
  PetscInt from = 0;
  if (const PetscInt per = Cycle(&from)) {
    o << "; the changes repeat with period " << per << " from iterate " << from << ": a cycle, not a slow approach, so more iterations do not help";
    if (relaxationHint) o << " (a smaller " << p << "relaxation may; for a reduced model, a cycle that damping does not remove says the training set does not resolve this parameter)";
  } else if (history.du.size() >= 10) { // not periodic to 1e-6, but not going down either (half_disks's ROM at du 5.7e-5 for 20 iterates: no word)
    const auto      last = history.du.end() - 10, mid = history.du.end() - 5;
    const PetscReal lo = *std::min_element(last, history.du.end()), hi = *std::max_element(last, history.du.end());
    PetscReal       before = 0, after = 0; // the means of the last 5 and the 5 before: a linear rate of 0.98 or worse
    for (auto it = last; it != mid; ++it) before += *it;
    for (auto it = mid; it != history.du.end(); ++it) after += *it;
    if (lo > rtolPrimal && after >= 0.9 * before) o << "; the primal change stalls between " << lo << " and " << hi << " over the last 10 iterations: not a slow approach, so more iterations do not help (for a reduced model: the training set does not resolve this parameter)";
  }
  o << cause;
  if (withHistory) {
    o << ". History:";
    for (size_t i = 0; i < history.du.size(); ++i) o << "\n  it " << i + 1 << ": du " << history.du[i] << ", dlambda " << history.dl[i] << ", active " << history.nactive[i];
  }
  return o.str();
}

} // namespace rbc
