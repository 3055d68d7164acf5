// bodypoint: the worker threads of a sweep or study, started so that a thread the system cannot create
// (`ulimit -v`, a process limit, `--threads 1000` on a small machine) leaves the work to those that did
// start instead of ending the process in std::terminate with its temporaries and locks in place.
#pragma once

#include "bodypoint/model.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace bodypoint {

/// The worker threads asked for (the command line's --threads, the Python module's threads): 0 is
/// every core; more than 1024 are not a machine, and each costs a stack: refused before any is made.
inline unsigned thread_count(long requested) {
  constexpr long kMaxThreads = 1024;
  if (requested < 0) throw Error("threads must be >= 0 (0: every core), got " + std::to_string(requested));
  if (requested > kMaxThreads) throw Error("threads must be at most " + std::to_string(kMaxThreads));
  if (requested > 0) return static_cast<unsigned>(requested);
  return std::max(1u, std::thread::hardware_concurrency());
}

class WorkerThreads {
 public:
  /// Starts up to n threads, each running work(); stops starting them at the first that fails.
  template <class F>
  WorkerThreads(unsigned n, F& work) {
    pool_.reserve(n);
    for (unsigned k = 0; k < n; ++k) {
      try {
        pool_.emplace_back(work);
      } catch (const std::system_error&) {
        break;
      }
    }
  }
  WorkerThreads(const WorkerThreads&) = delete;
  WorkerThreads& operator=(const WorkerThreads&) = delete;
  ~WorkerThreads() { join(); }

  /// How many started.
  [[nodiscard]] std::size_t size() const { return pool_.size(); }
  void join() {
    for (std::thread& t : pool_)
      if (t.joinable()) t.join();
  }

 private:
  std::vector<std::thread> pool_;
};

/// Runs f(i) for every i < n on up to `threads` threads (this one among them), each taking the next i. The
/// first exception a call throws stops the handing out and is rethrown once the running calls have finished.
template <class F>
void parallel_for(std::size_t n, unsigned threads, F&& f) {
  std::atomic<std::size_t> next{0};
  std::mutex mutex;  // the first error
  std::exception_ptr error;
  auto worker = [&] {
    try {
      for (std::size_t i; (i = next++) < n;) f(i);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex);
      if (!error) error = std::current_exception();
      next = n;
    }
  };
  {
    const WorkerThreads pool(static_cast<unsigned>(std::min<std::size_t>(std::max(threads, 1u), std::max<std::size_t>(n, 1))) - 1,
                             worker);
    worker();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace bodypoint
