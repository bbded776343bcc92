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
#include <map>
#include <memory>
#include <mutex>

namespace evio::simulator {

/// The TBB arena of `threads` workers (0: all cores), made on first use and
/// kept for the process (never destroyed). One arena for all the simulator's
/// parallel loops: an arena made per loop (thousands per simulated second)
/// is joined by the worker threads only after a wake-up, often after the
/// calling thread has done most of a short loop alone.
inline tbb::task_arena& sharedArena(int threads) {
  static std::mutex mutex;
  static auto* arenas = new std::map<int, std::unique_ptr<tbb::task_arena>>();
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<tbb::task_arena>& arena = (*arenas)[threads];
  if (!arena) arena = threads > 0 ? std::make_unique<tbb::task_arena>(threads) : std::make_unique<tbb::task_arena>();
  return *arena;
}

template <class F>
void parallelFor(int threads, std::size_t count, std::size_t grain, const F& f) {
  if (threads == 1 || count <= 1) {
    for (std::size_t i = 0; i < count; ++i) f(i);
    return;
  }
  sharedArena(threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
  });
}

}  // namespace evio::simulator
