#pragma once
// Hands work from one producer thread to one consumer thread, in order
// (pipeline.cpp: reading and tracking on the caller's thread, the backend,
// health monitor and writer on the consumer thread). A ring of `capacity`
// reusable slots: the producer fills slot() and push()es it, blocking while
// all slots are taken (memory stays bounded); the consumer thread calls
// `consume` on each pushed slot, oldest first. An exception thrown by
// `consume` stops the consuming (the rest is drained unconsumed) and is
// rethrown by finish().

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace evio::estimator {

template <class Work>
class HandoffQueue {
 public:
  HandoffQueue(std::size_t capacity, std::function<void(Work&)> consume)
      : ring_(capacity), consume_(std::move(consume)), thread_([this] { consumerLoop(); }) {}
  ~HandoffQueue() {
    try {
      finish();
    } catch (...) {  // finish() was not called: the caller is unwinding already
    }
  }
  HandoffQueue(const HandoffQueue&) = delete;
  HandoffQueue& operator=(const HandoffQueue&) = delete;

  /// The next free slot (waits while every slot holds unconsumed work).
  Work& slot() {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [this] { return count_ < ring_.size(); });
    return ring_[(head_ + count_) % ring_.size()];
  }
  /// Publishes the slot last returned by slot().
  void push() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++count_;
    }
    work_.notify_one();
  }
  /// True once `consume` threw (the producer may stop early).
  bool failed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_ != nullptr;
  }
  /// Waits until every pushed slot is consumed and stops the thread;
  /// rethrows the exception `consume` threw, if any.
  void finish() {
    if (thread_.joinable()) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        done_ = true;
      }
      work_.notify_one();
      thread_.join();
    }
    if (error_) {
      std::exception_ptr e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
  }

 private:
  void consumerLoop() {
    while (true) {
      Work* w = nullptr;
      bool skip = false;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        work_.wait(lock, [this] { return count_ > 0 || done_; });
        if (count_ == 0) return;  // done and drained
        w = &ring_[head_];
        skip = error_ != nullptr;
      }
      if (!skip) {
        try {
          consume_(*w);
        } catch (...) {
          std::lock_guard<std::mutex> lock(mutex_);
          error_ = std::current_exception();
        }
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        head_ = (head_ + 1) % ring_.size();
        --count_;
      }
      space_.notify_one();
    }
  }

  std::vector<Work> ring_;
  std::function<void(Work&)> consume_;
  mutable std::mutex mutex_;
  std::condition_variable work_;
  std::condition_variable space_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  bool done_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts after the members above exist
};

}  // namespace evio::estimator
