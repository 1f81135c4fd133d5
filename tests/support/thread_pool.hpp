#pragma once
// A small job system standing in for an engine's: N worker threads that model
// infolerp::executor. Tests use it to show results do not depend on the thread count.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>
#include "infolerp/core/executor.hpp"

namespace infolerp::support {

class thread_pool_executor {
 public:
  explicit thread_pool_executor(unsigned workers) : workers_(std::max(1u, workers)) {}
  // Spawns the workers for each call (tests only; an engine would keep them).
  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    if (n == 0) return;
    const std::size_t chunks = chunk_count(n, grain);  // chunk indices, so no grain can wrap a bound
    std::atomic<std::size_t> next{0};
    auto work = [&] {
      for (;;) {
        const std::size_t c = next.fetch_add(1);
        if (c >= chunks) return;
        const chunk_bounds r = chunk_at(n, grain, c);
        fn(r.begin, r.end);
      }
    };
    std::vector<std::thread> threads;
    for (unsigned i = 1; i < workers_; ++i) threads.emplace_back(work);
    work();
    for (auto& t : threads) t.join();
  }
  unsigned workers() const { return workers_; }

 private:
  unsigned workers_;
};

}  // namespace infolerp::support
