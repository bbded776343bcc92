#pragma once
/// @file worker_pool.h
/// A fixed team of threads for work split into a fixed partition: run(task)
/// calls task(k) once for every k in [0, size()), part 0 on the calling
/// thread and part k on worker thread k, and returns when all parts are done.
/// Which thread runs which part never depends on scheduling, so a caller that
/// gives each part its own data and merges the parts' results in part order
/// gets the same result for any number of threads (EkltTracker's features).
///
/// The workers sleep on a condition variable between calls (no spinning: the
/// machine may be shared). An exception thrown by a part is rethrown by run()
/// after all parts have finished (the first one in part order).

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace evio::estimator {

class WorkerPool {
 public:
  /// `size` ≥ 1 parts; size − 1 threads are started.
  explicit WorkerPool(int size);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int size() const { return static_cast<int>(threads_.size()) + 1; }

  /// CPU seconds spent in the parts so far (thread CPU clocks): by the
  /// worker threads (part 0, on the caller's thread, not included), by all
  /// parts, and the critical path: the sum over runs of the slowest part's
  /// CPU time, i.e. what the runs would take on idle cores (thread wake-ups
  /// not counted).
  struct Cpu {
    double workers_s = 0.0;
    double parts_s = 0.0;
    double critical_path_s = 0.0;
    /// Wall seconds the calling thread waited for the workers after its own
    /// part (it uses no CPU then; the pipeline's stage split leaves it out).
    double wait_s = 0.0;
  };
  Cpu cpu() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return cpu_;
  }

  /// Calls task(k) for k = 0 … size()−1 (k = 0 here, the others on the
  /// workers) and waits for all of them. Allocates nothing.
  template <class Task>
  void run(Task& task) {
    runParts(&callTask<Task>, &task);
  }

 private:
  using PartFn = void (*)(void* context, int part);
  template <class Task>
  static void callTask(void* context, int part) {
    (*static_cast<Task*>(context))(part);
  }
  void runParts(PartFn fn, void* context);
  void workerLoop(int part);
  void runPart(int part);

  std::vector<std::thread> threads_;
  mutable std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  PartFn fn_ = nullptr;
  void* context_ = nullptr;
  std::uint64_t generation_ = 0;  // incremented by every run
  int pending_ = 0;               // worker parts not finished in this run
  bool stop_ = false;
  std::vector<double> part_cpu_s_;  // of the current run, per part
  Cpu cpu_;
  std::vector<std::exception_ptr> errors_;  // per part
};

}  // namespace evio::estimator
