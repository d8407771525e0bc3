// src/rom/fork_join.cpp: the fork-join pool of the online solve's threads (include/rbcontact/fork_join.hpp).
#include "rbcontact/fork_join.hpp"

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#endif

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define RBC_PAUSE() _mm_pause()
#else
#define RBC_PAUSE() std::this_thread::yield()
#endif

namespace rbc {

namespace {
// Spins of a worker waiting for the next region before it sleeps (about 50-100 us: the gaps between the regions of
// one Kacanov iterate are shorter, those between solves may be longer)
constexpr int kSpin = 20000;
} // namespace

void ForkJoin::SetThreads(int n)
{
  Stop();
  stop_ = false;
  // the generation before any region of these workers (a worker may start only after the first Run)
  const unsigned long g = generation_.load();
  for (int t = 1; t < n; ++t) {
    workers_.emplace_back([this, t, g] { Work(t, g); });
    Pin(workers_.back());
  }
}

void ForkJoin::SetCpus(const std::vector<int> &cpus)
{
  cpus_ = cpus;
  for (auto &w : workers_) Pin(w);
}

#if defined(__linux__)
static bool ToSet(const std::vector<int> &cpus, cpu_set_t *set)
{
  CPU_ZERO(set);
  for (int c : cpus)
    if (c >= 0 && c < CPU_SETSIZE) CPU_SET(c, set);
  return CPU_COUNT(set) > 0;
}
#endif

void ForkJoin::Pin(std::thread &w) const
{
#if defined(__linux__)
  cpu_set_t set;
  if (!cpus_.empty() && ToSet(cpus_, &set)) (void)pthread_setaffinity_np(w.native_handle(), sizeof(set), &set);
#else
  (void)w;
#endif
}

std::vector<int> ForkJoin::CallerCpus()
{
  std::vector<int> cpus;
#if defined(__linux__)
  cpu_set_t set;
  CPU_ZERO(&set);
  if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) cpus.push_back(c);
#endif
  return cpus;
}

bool ForkJoin::SetCallerCpus(const std::vector<int> &cpus)
{
#if defined(__linux__)
  cpu_set_t set;
  return ToSet(cpus, &set) && pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
#else
  (void)cpus;
  return false;
#endif
}

void ForkJoin::Stop()
{
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  for (auto &w : workers_) w.join();
  workers_.clear();
}

void ForkJoin::Run(const std::function<void(int)> &f)
{
  if (workers_.empty()) {
    f(0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m_);
    job_ = &f;
    pending_.store((int)workers_.size());
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  f(0);
  while (pending_.load(std::memory_order_acquire) > 0) RBC_PAUSE();
}

void ForkJoin::Work(int t, unsigned long seen)
{
  for (;;) {
    int spins = 0;
    while (generation_.load(std::memory_order_acquire) == seen && spins < kSpin) {
      RBC_PAUSE();
      ++spins;
    }
    const std::function<void(int)> *job;
    {
      std::unique_lock<std::mutex> lock(m_);
      wake_.wait(lock, [&] { return generation_.load() != seen; });
      seen = generation_.load();
      if (stop_) return;
      job = job_;
    }
    (*job)(t);
    pending_.fetch_sub(1, std::memory_order_release);
  }
}

} // namespace rbc
