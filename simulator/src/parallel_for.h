#pragma once
/// @file parallel_for.h
/// f(i) for i in [0, count): in order on the calling thread when threads is
/// 1 (or there is one item), else on a TBB arena of `threads` workers
/// (0: all cores) in chunks of `grain`. Each f(i) must write only its own
/// outputs, so the result does not depend on the thread count.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstddef>

namespace evio::simulator {

template <class F>
void parallelFor(int threads, std::size_t count, std::size_t grain, const F& f) {
  if (threads == 1 || count <= 1) {
    for (std::size_t i = 0; i < count; ++i) f(i);
    return;
  }
  tbb::task_arena arena = threads > 0 ? tbb::task_arena(threads) : tbb::task_arena();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
  });
}

}  // namespace evio::simulator
