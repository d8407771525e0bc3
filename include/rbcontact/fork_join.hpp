// include/rbcontact/fork_join.hpp: the online solve's threads (-rom_threads, docs/online.md "Threads"): a fork-join pool of
// n - 1 persistent workers and the calling thread. Run(f) calls f(t) for t = 0..n-1 (t = 0 on the caller) and
// returns when every call has returned. Workers spin briefly between the regions of one solve, then sleep, so an
// idle pool takes no core. A worker starts on the CPUs of the thread that creates it (its affinity mask): under
// mpirun, which binds each rank to one core by default, n threads then share that core unless SetCpus widens them
// (validate does, for the cores of the ranks that wait asleep) or the job runs with mpirun --bind-to none.
#pragma once
#include <petscsys.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace rbc {

class ForkJoin {
public:
  ForkJoin() = default;
  ~ForkJoin() { Stop(); }
  ForkJoin(const ForkJoin &)            = delete;
  ForkJoin &operator=(const ForkJoin &) = delete;
  // n >= 1 threads in all (the caller and n - 1 workers, started here)
  void SetThreads(int n);
  int  Threads() const { return (int)workers_.size() + 1; }
  void Run(const std::function<void(int)> &f);
  // The workers' CPUs (Linux CPU numbers; empty: those they started with), for the present workers and later ones
  void SetCpus(const std::vector<int> &cpus);

  // The CPUs the calling thread may run on (its affinity mask; empty where the system does not say)
  static std::vector<int> CallerCpus();
  // Set the calling thread's CPUs (false where the system refuses or cannot)
  static bool SetCallerCpus(const std::vector<int> &cpus);

  // [begin, end) of part t of n equal parts of [0, count)
  static void Part(PetscInt count, int t, int n, PetscInt *begin, PetscInt *end)
  {
    *begin = count * t / n;
    *end   = count * (t + 1) / n;
  }
  // f(begin, end, t) for each part t of [0, count) on the pool's threads (pool null: f(0, count, 0) on the caller)
  template <class F>
  static void ForParts(ForkJoin *pool, PetscInt count, F &&f)
  {
    if (!pool) return (void)f((PetscInt)0, count, 0);
    const int n = pool->Threads();
    pool->Run([&](int t) {
      PetscInt a, b;
      Part(count, t, n, &a, &b);
      f(a, b, t);
    });
  }

private:
  void Stop();
  void Work(int t, unsigned long seen);
  void Pin(std::thread &w) const;
  std::vector<std::thread>        workers_;
  std::vector<int>                cpus_;
  std::mutex                      m_;
  std::condition_variable         wake_;
  const std::function<void(int)> *job_ = nullptr;
  std::atomic<unsigned long>      generation_{0};
  std::atomic<int>                pending_{0};
  bool                            stop_ = false;
};

// A member that copies as an empty pool (a copied ReducedModel starts its own threads when it first needs them)
struct ForkJoinHolder {
  ForkJoinHolder() = default;
  ForkJoinHolder(const ForkJoinHolder &o) : cpus(o.cpus) {}
  ForkJoinHolder &operator=(const ForkJoinHolder &o)
  {
    SetCpus(o.cpus);
    return *this;
  }
  std::unique_ptr<ForkJoin> pool;
  std::vector<int>          cpus; // the workers' CPUs (ForkJoin::SetCpus; empty: inherited)
  // the pool with n threads (created or resized on demand)
  ForkJoin &Get(int n)
  {
    if (!pool) pool = std::make_unique<ForkJoin>();
    if (pool->Threads() != n) {
      pool->SetCpus(cpus);
      pool->SetThreads(n);
    }
    return *pool;
  }
  void SetCpus(const std::vector<int> &c)
  {
    cpus = c;
    if (pool) pool->SetCpus(c);
  }
};

} // namespace rbc
