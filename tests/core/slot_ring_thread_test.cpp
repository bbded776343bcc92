// SlotRingThread's two ways in and its destruction policies
// (core/slot_ring_thread.h); push(fill), the error path and dropping on
// destruction are tested with the simulator's writers
// (tests/simulator/writer_thread_test.cpp).
#include "evio/core/slot_ring_thread.h"

#include <gtest/gtest.h>

#include <future>
#include <stdexcept>
#include <vector>

#include "evio/core/error.h"

namespace evio {
namespace {

using Ring = SlotRingThread<std::vector<int>>;

TEST(SlotRingThread, SlotThenPushIsConsumedInOrderInReusedSlots) {
  std::vector<int> seen;
  Ring ring(2, [&](std::vector<int>& slot) { seen.insert(seen.end(), slot.begin(), slot.end()); },
            Ring::OnDestroy::kConsumeQueued);
  for (int i = 0; i < 50; ++i) {
    std::vector<int>& slot = ring.slot();
    slot.assign({2 * i, 2 * i + 1});  // filled outside the lock
    ring.push();
  }
  ring.finish();
  ASSERT_EQ(seen.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(seen[i], i);
  EXPECT_THROW(ring.slot(), Error);  // after finish
}

// The pipeline's policy: destroyed while its producer unwinds, the ring still
// consumes every queued slot (the backend takes every item read before the error).
TEST(SlotRingThread, DestructionConsumesQueuedSlotsWhenAskedTo) {
  std::promise<void> gate;
  std::shared_future<void> open = gate.get_future().share();
  int consumed = 0;
  {
    Ring ring(8, [&](std::vector<int>&) {
      open.wait();
      ++consumed;
    }, Ring::OnDestroy::kConsumeQueued);
    for (int i = 0; i < 8; ++i) {
      ring.slot();
      ring.push();
    }
    gate.set_value();
  }
  EXPECT_EQ(consumed, 8);
}

// slot() reports the consumer's failure: the producer neither hangs nor
// fills slots that will not be consumed; failed() says so beforehand.
TEST(SlotRingThread, SlotRethrowsTheConsumersError) {
  Ring ring(1, [](std::vector<int>& slot) {
    if (slot.at(0) == 3) throw std::runtime_error("backend failed at 3");
  }, Ring::OnDestroy::kConsumeQueued);
  bool thrown = false;
  for (int i = 0; i < 1000 && !thrown; ++i) {
    try {
      ring.slot().assign(1, i);
      ring.push();
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "backend failed at 3");
      thrown = true;
    }
  }
  EXPECT_TRUE(thrown);
  EXPECT_TRUE(ring.failed());
  EXPECT_THROW(ring.finish(), std::runtime_error);
}

}  // namespace
}  // namespace evio
