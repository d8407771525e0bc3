// tests/test_fork_join.cpp: the online solve's thread pool (include/rbcontact/fork_join.hpp, -rom_threads). Run calls
// f(t) once for every t on distinct threads and returns after all; many regions in a row (the generation counter);
// workers started after earlier regions (the bug of a worker that missed its first region); Part's ranges tile
// [0, count); and the CPUs: CallerCpus is the thread's affinity mask as the system reports it (sched_getaffinity),
// SetCallerCpus changes and restores it, SetCpus puts every worker, present and later, on the given CPUs (each
// worker reads its own mask inside a region), the fix for mpirun's binding of a rank to one core (docs/online.md
// "Threads").
#include "rbcontact/fork_join.hpp"
#include "test_check.hpp"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <set>
#include <thread>
#include <vector>

using namespace rbc;
using rbctest::Check;

static std::vector<int> SystemCpus() // the calling thread's mask, read without ForkJoin
{
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof(set), &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) cpus.push_back(c);
  return cpus;
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  const MPI_Comm self = PETSC_COMM_SELF;

  // CPUs: first the mask mpirun gave (one core by default), then every CPU of the machine the system allows, so that
  // the checks below see masks of different sizes where the machine has more than one CPU (and the workers of the
  // Run checks are not all spinning on one core)
  const std::vector<int> given = SystemCpus();
  PetscCall(Check(self, !given.empty() && ForkJoin::CallerCpus() == given, "CallerCpus = the thread's affinity mask (sched_getaffinity)", (double)given.size(), 0));
  {
    std::vector<int> all;
    for (int c = 0; c < (int)std::thread::hardware_concurrency(); ++c) all.push_back(c);
    (void)ForkJoin::SetCallerCpus(all);
  }
  const std::vector<int> mine = SystemCpus();
  PetscCall(PetscPrintf(self, "  (the thread's mask: %d CPU(s) from mpirun, %d after widening)\n", (int)given.size(), (int)mine.size()));
  PetscCall(Check(self, mine.size() >= given.size() && ForkJoin::CallerCpus() == mine, "CallerCpus after widening = the mask the system reports", (double)mine.size(), 0));

  // Part: n parts of [0, count) in order, without gaps or overlaps
  {
    bool ok = true;
    for (PetscInt count : {0, 1, 5, 3679})
      for (int n : {1, 2, 3, 7}) {
        PetscInt next = 0;
        for (int t = 0; t < n; ++t) {
          PetscInt a, b;
          ForkJoin::Part(count, t, n, &a, &b);
          ok = ok && a == next && b >= a;
          next = b;
        }
        ok = ok && next == count;
      }
    PetscCall(Check(self, ok, "Part: the parts tile [0, count) in order", ok ? 0 : 1, 0));
  }

  // Run: every t once, on distinct threads, over many regions; then more workers than before
  for (int n : {1, 2, 3, 4}) {
    ForkJoin pool;
    pool.SetThreads(n);
    int  bad = 0;
    long sum = 0;
    for (int region = 0; region < 500; ++region) {
      std::vector<std::atomic<int>>         calls(n);
      std::vector<std::thread::id>          ids(n);
      std::atomic<long>                     acc{0};
      for (auto &c : calls) c = 0;
      pool.Run([&](int t) {
        ++calls[t];
        ids[t] = std::this_thread::get_id();
        acc += t + 1;
      });
      for (int t = 0; t < n; ++t) bad += calls[t] != 1;
      bad += (int)std::set<std::thread::id>(ids.begin(), ids.end()).size() != n;
      bad += ids[0] != std::this_thread::get_id(); // part 0 on the caller
      sum += acc;
    }
    PetscCall(Check(self, pool.Threads() == n && bad == 0 && sum == 500L * n * (n + 1) / 2, "Run: 500 regions, each t once on its own thread (t = 0 the caller)", bad, 0));
  }
  {
    ForkJoin pool;
    pool.SetThreads(2);
    std::atomic<int> c{0};
    for (int i = 0; i < 50; ++i) pool.Run([&](int) { ++c; });
    pool.SetThreads(3); // workers started after 50 regions must not wait for one already gone
    for (int i = 0; i < 50; ++i) pool.Run([&](int) { ++c; });
    PetscCall(Check(self, c == 50 * 2 + 50 * 3, "workers started after earlier regions take part in the next ones", c, 250));
  }

  {
    const std::vector<int> one = {mine.back()};
    bool                   ok  = ForkJoin::SetCallerCpus(one) && SystemCpus() == one;
    ok                         = ok && ForkJoin::SetCallerCpus(mine) && SystemCpus() == mine;
    PetscCall(Check(self, ok, "SetCallerCpus sets the thread's mask, and restores it", ok ? 0 : 1, 0));
  }
  {
    // workers on one CPU, set before they start and while they run; the caller keeps its own mask
    const std::vector<int> one = {mine.front()};
    ForkJoin               pool;
    pool.SetCpus(one);
    pool.SetThreads(3);
    std::vector<std::vector<int>> seen(3);
    pool.Run([&](int t) { seen[t] = ForkJoin::CallerCpus(); });
    bool ok = seen[0] == mine && seen[1] == one && seen[2] == one;
    pool.SetCpus(mine); // widened while running (validate: the cores of the ranks that wait)
    pool.Run([&](int t) { seen[t] = ForkJoin::CallerCpus(); });
    ok = ok && seen[1] == mine && seen[2] == mine;
    PetscCall(Check(self, ok, "SetCpus: the workers' masks, before they start and while they run", ok ? 0 : 1, 0));
  }
  {
    // a holder keeps the CPUs for the pool it creates later, and a copy keeps them (a copied ReducedModel)
    ForkJoinHolder h;
    h.SetCpus({mine.front()});
    ForkJoinHolder                c(h);
    std::vector<std::vector<int>> seen(2);
    c.Get(2).Run([&](int t) { seen[t] = ForkJoin::CallerCpus(); });
    const bool ok = c.cpus == std::vector<int>{mine.front()} && seen[1] == std::vector<int>{mine.front()};
    PetscCall(Check(self, ok, "ForkJoinHolder: the CPUs reach a pool created later, and survive a copy", ok ? 0 : 1, 0));
  }

  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_fork_join: %d failure(s)\n", rbctest::failures));
  PetscCall(PetscFinalize());
  return rbctest::failures ? 1 : 0;
}
