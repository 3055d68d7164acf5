// bodypoint: the worker threads of a sweep or study, started so that a thread the system cannot create
// (`ulimit -v`, a process limit, `--threads 1000` on a small machine) leaves the work to those that did
// start instead of ending the process in std::terminate with its temporaries and locks in place.
#pragma once

#include <system_error>
#include <thread>
#include <vector>

namespace bodypoint {

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

}  // namespace bodypoint
