#pragma once
/// @file writer_thread.h
/// A thread of its own for a sequential consumer (the sequence folder's
/// writers), fed through a bounded ring of reusable slots.
///
/// push(fill) waits for a free slot, lets `fill` write the job into it (the
/// slot keeps its buffers from its earlier use, so a job is copied into
/// memory that is already there) and hands it to the thread, which calls
/// consume(slot) on the slots in push order. Memory is flat: `capacity`
/// slots, whatever the run's length.
///
/// Errors: the first exception of consume() stops the consumer; the slots
/// still queued and pushed later are dropped unconsumed, so a producer never
/// waits for ever on a failed consumer, and the next push() or finish()
/// rethrows that exception on the producer's thread. The destructor (e.g.
/// while an exception of the producer unwinds) drops what is queued and
/// joins the thread; it never throws.
///
/// push() may be called from several threads; jobs are consumed in the
/// order their push() calls took the lock (one producer: its call order).

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "evio/core/error.h"

namespace evio::simulator {

template <class Slot>
class WriterThread {
 public:
  /// Starts the thread. capacity >= 1 slots, each default-constructed.
  WriterThread(std::size_t capacity, std::function<void(Slot&)> consume)
      : slots_(capacity), consume_(std::move(consume)) {
    require(capacity >= 1, "WriterThread: capacity must be at least 1");
    thread_ = std::thread([this] { run(); });
  }
  ~WriterThread() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      drop_ = true;
    }
    stop();
  }
  WriterThread(const WriterThread&) = delete;
  WriterThread& operator=(const WriterThread&) = delete;

  /// Waits for a free slot, calls fill(slot) and queues the slot. Rethrows
  /// the consumer's error, if it failed (then fill is not called). Throws
  /// Error after finish(). An exception of fill() leaves the slot unqueued.
  template <class Fill>
  void push(Fill&& fill) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (finished_) throw Error("WriterThread: push after finish");
    space_.wait(lock, [this] { return queued_ < slots_.size() || error_ != nullptr; });
    if (error_) std::rethrow_exception(error_);
    Slot& slot = slots_[(head_ + queued_) % slots_.size()];
    fill(slot);
    ++queued_;
    ready_.notify_one();
  }

  /// Waits until every queued slot is consumed and ends the thread;
  /// rethrows the consumer's error. Later calls return (or throw) the same.
  void finish() {
    stop();
    if (error_) std::rethrow_exception(error_);
  }

  /// Slots queued and not yet consumed (for tests and diagnostics).
  std::size_t queued() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return queued_;
  }
  std::size_t capacity() const { return slots_.size(); }

 private:
  void stop() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
      ready_.notify_one();
    }
    if (thread_.joinable()) thread_.join();
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      ready_.wait(lock, [this] { return queued_ > 0 || finished_; });
      if (queued_ == 0) return;  // finished and drained
      Slot& slot = slots_[head_];
      if (!error_ && !drop_) {
        lock.unlock();  // the producer fills other slots meanwhile
        try {
          consume_(slot);
        } catch (...) {
          lock.lock();
          error_ = std::current_exception();
          lock.unlock();
        }
        lock.lock();
      }
      head_ = (head_ + 1) % slots_.size();
      --queued_;
      space_.notify_all();
    }
  }

  std::vector<Slot> slots_;
  std::function<void(Slot&)> consume_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;  ///< a slot was queued, or finish
  std::condition_variable space_;  ///< a slot was freed, or the consumer failed
  std::size_t head_ = 0;           ///< the oldest queued slot
  std::size_t queued_ = 0;
  bool finished_ = false;
  bool drop_ = false;              ///< destruction: queued slots are not consumed
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace evio::simulator
