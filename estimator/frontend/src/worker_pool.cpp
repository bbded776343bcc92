#include "evio/estimator/frontend/worker_pool.h"

#include "evio/core/error.h"
#include "evio/core/stopwatch.h"

namespace evio::estimator {

WorkerPool::WorkerPool(int size) {
  require(size >= 1, "WorkerPool: size must be >= 1");
  errors_.resize(static_cast<std::size_t>(size));
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
  runPart(0);
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
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
      worker_cpu_s_ += cpu;
      last = --pending_ == 0;
    }
    if (last) done_.notify_one();
  }
}

}  // namespace evio::estimator
