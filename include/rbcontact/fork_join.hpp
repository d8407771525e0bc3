// include/rbcontact/fork_join.hpp: the online solve's threads (-rom_threads, docs/online.md "Threads"): a fork-join pool of
// n - 1 persistent workers and the calling thread. Run(f) calls f(t) for t = 0..n-1 (t = 0 on the caller) and
// returns when every call has returned. Workers spin briefly between the regions of one solve, then sleep, so an
// idle pool takes no core.
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

  // [begin, end) of part t of n equal parts of [0, count)
  static void Part(PetscInt count, int t, int n, PetscInt *begin, PetscInt *end)
  {
    *begin = count * t / n;
    *end   = count * (t + 1) / n;
  }

private:
  void Stop();
  void Work(int t, unsigned long seen);
  std::vector<std::thread>        workers_;
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
  ForkJoinHolder(const ForkJoinHolder &) {}
  ForkJoinHolder &operator=(const ForkJoinHolder &) { return *this; }
  std::unique_ptr<ForkJoin> pool;
  // the pool with n threads (created or resized on demand)
  ForkJoin &Get(int n)
  {
    if (!pool) pool = std::make_unique<ForkJoin>();
    if (pool->Threads() != n) pool->SetThreads(n);
    return *pool;
  }
};

} // namespace rbc
