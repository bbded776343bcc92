#include "evio/estimator/frontend/worker_pool.h"

#include <algorithm>

#include "evio/core/error.h"
#include "evio/core/stopwatch.h"

namespace evio::estimator {

WorkerPool::WorkerPool(int size) {
  require(size >= 1, "WorkerPool: size must be >= 1");
  errors_.resize(static_cast<std::size_t>(size));
  part_cpu_s_.assign(static_cast<std::size_t>(size), 0.0);
  threads_.reserve(static_cast<std::size_t>(size - 1));
  for (int k = 1; k < size; ++k) threads_.emplace_back([this, k] { workerLoop(k); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void WorkerPool::runPart(int part) {
  try {
    fn_(context_, part);
  } catch (...) {
    errors_[static_cast<std::size_t>(part)] = std::current_exception();
  }
}

void WorkerPool::runParts(PartFn fn, void* context) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    fn_ = fn;
    context_ = context;
    pending_ = static_cast<int>(threads_.size());
    ++generation_;
  }
  start_.notify_all();
  const double cpu0 = Stopwatch::threadCpuSeconds();
  runPart(0);
  const double part0_cpu = Stopwatch::threadCpuSeconds() - cpu0;
  {
    const Stopwatch waiting;
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
    cpu_.wait_s += waiting.seconds();
    part_cpu_s_[0] = part0_cpu;
    double slowest = 0.0;
    for (double c : part_cpu_s_) {
      cpu_.parts_s += c;
      slowest = std::max(slowest, c);
    }
    cpu_.critical_path_s += slowest;
  }
  for (std::exception_ptr& e : errors_) {
    if (!e) continue;
    std::exception_ptr first = e;
    for (std::exception_ptr& other : errors_) other = nullptr;
    std::rethrow_exception(first);
  }
}

void WorkerPool::workerLoop(int part) {
  std::uint64_t seen = 0;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    const double cpu0 = Stopwatch::threadCpuSeconds();
    runPart(part);
    const double cpu = Stopwatch::threadCpuSeconds() - cpu0;
    bool last = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      cpu_.workers_s += cpu;
      part_cpu_s_[static_cast<std::size_t>(part)] = cpu;
      last = --pending_ == 0;
    }
    if (last) done_.notify_one();
  }
}

}  // namespace evio::estimator
