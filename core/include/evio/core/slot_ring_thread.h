#pragma once
/// @file slot_ring_thread.h
/// A thread of its own for a sequential consumer, fed through a bounded ring
/// of reusable slots: the simulator's file writers (AsyncSequenceWriter) and
/// the estimator's backend side (pipeline.cpp, backend_thread).
///
/// The producer fills a free slot (the slot keeps its buffers from its
/// earlier use, so a job is copied into memory that is already there) and
/// queues it; the thread calls consume(slot) on the slots in queue order.
/// Memory is flat: `capacity` slots, whatever the run's length. Two ways in:
///  - slot() then push(): one producer fills the slot outside the lock, so
///    filling overlaps the consumer (the pipeline's tracking and backend);
///  - push(fill): fill runs under the lock, so several threads may push
///    (the simulator's event and frame stages); jobs are consumed in the
///    order their push() calls took the lock.
///
/// Errors: the first exception of consume() stops the consuming; slots still
/// queued and pushed later are drained unconsumed, so a producer never waits
/// for ever on a failed consumer. slot(), push(fill) and finish() rethrow
/// that exception on the producer's thread (finish() on every later call).
///
/// Destruction (e.g. while an exception of the producer unwinds) joins the
/// thread and never throws; by `OnDestroy` it first consumes what is queued
/// (the pipeline: the backend still takes every item read before a bad
/// input, so the trajectory before it is kept) or drops it (the writers:
/// files that will not be completed need no more data).

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "evio/core/error.h"

namespace evio {

template <class Slot>
class SlotRingThread {
 public:
  enum class OnDestroy { kConsumeQueued, kDropQueued };

  /// Starts the thread. capacity >= 1 slots, each default-constructed.
  SlotRingThread(std::size_t capacity, std::function<void(Slot&)> consume, OnDestroy on_destroy)
      : slots_(capacity), consume_(std::move(consume)), on_destroy_(on_destroy) {
    require(capacity >= 1, "SlotRingThread: capacity must be at least 1");
    thread_ = std::thread([this] { run(); });
  }
  ~SlotRingThread() {
    if (on_destroy_ == OnDestroy::kDropQueued) {
      const std::lock_guard<std::mutex> lock(mutex_);
      drop_ = true;
    }
    stop();
  }
  SlotRingThread(const SlotRingThread&) = delete;
  SlotRingThread& operator=(const SlotRingThread&) = delete;

  /// The next free slot, for one producer (waits while every slot is
  /// queued). Rethrows the consumer's error; throws Error after finish().
  Slot& slot() {
    std::unique_lock<std::mutex> lock(mutex_);
    waitForSpace(lock);
    return slots_[(head_ + queued_) % slots_.size()];
  }
  /// Queues the slot last returned by slot().
  void push() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      ++queued_;
    }
    ready_.notify_one();
  }
  /// Waits for a free slot, calls fill(slot) under the lock and queues the
  /// slot; several producers may call it. Rethrows the consumer's error (then
  /// fill is not called); throws Error after finish(). An exception of
  /// fill() leaves the slot unqueued.
  template <class Fill>
  void push(Fill&& fill) {
    std::unique_lock<std::mutex> lock(mutex_);
    waitForSpace(lock);
    fill(slots_[(head_ + queued_) % slots_.size()]);
    ++queued_;
    ready_.notify_one();
  }

  /// True once consume() threw (the producer may stop early).
  bool failed() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return error_ != nullptr;
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
  void waitForSpace(std::unique_lock<std::mutex>& lock) {
    if (finished_) throw Error("SlotRingThread: push after finish");
    space_.wait(lock, [this] { return queued_ < slots_.size() || error_ != nullptr; });
    if (error_) std::rethrow_exception(error_);
  }

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
  OnDestroy on_destroy_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;  ///< a slot was queued, or finish
  std::condition_variable space_;  ///< a slot was freed, or the consumer failed
  std::size_t head_ = 0;           ///< the oldest queued slot
  std::size_t queued_ = 0;
  bool finished_ = false;
  bool drop_ = false;              ///< destruction with kDropQueued: queued slots are not consumed
  std::exception_ptr error_;
  std::thread thread_;             ///< started in the constructor, after the members above
};

}  // namespace evio
