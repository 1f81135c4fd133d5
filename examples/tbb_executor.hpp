#pragma once
// An infolerp executor (core/executor.hpp) over oneTBB: parallel_for on a blocked_range with
// the simple partitioner, which splits until every range is at most `grain` long, as the
// executor contract asks; the work runs in the adaptor's task_arena (its thread count).
// Results are the same bits as with the serial and OpenMP executors: the library reduces per
// fixed chunk and combines in order, whatever ranges the executor hands out.
#include <cstddef>
#include <memory>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

namespace examples {

class tbb_executor {
 public:
  // threads = 0: oneTBB's default (all cores).
  explicit tbb_executor(int threads = 0)
      : arena_(std::make_shared<tbb::task_arena>(threads > 0 ? threads : int{tbb::task_arena::automatic})) {}

  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    if (n == 0) return;
    const std::size_t g = grain > 0 ? grain : 1;
    arena_->execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, n, g),
          [&](const tbb::blocked_range<std::size_t>& r) { fn(r.begin(), r.end()); }, tbb::simple_partitioner{});
    });
  }

 private:
  std::shared_ptr<tbb::task_arena> arena_;  // shared: the executor is copied by value into calls
};

}  // namespace examples
