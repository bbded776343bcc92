// The slot ring thread with the writers' policy (core/slot_ring_thread.h,
// queued jobs dropped on destruction) and the sequence writer on it
// (AsyncSequenceWriter): jobs consumed in push order in at most `capacity`
// reused slots, the consumer's first error rethrown on the producer's thread
// (at a later push or at finish) without a hang, queued jobs dropped on
// destruction; the asynchronous writer's files are byte for byte those of
// SequenceWriter, and a failed write completes no file.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <functional>
#include <future>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/slot_ring_thread.h"
#include "evio/simulator/sequence_writer.h"
#include "temp_dir.h"

namespace evio::simulator {
namespace {

namespace fs = std::filesystem;

/// The ring with the writers' policy: queued jobs dropped on destruction.
template <class Slot>
struct WriterThread : SlotRingThread<Slot> {
  WriterThread(std::size_t capacity, std::function<void(Slot&)> consume)
      : SlotRingThread<Slot>(capacity, std::move(consume), SlotRingThread<Slot>::OnDestroy::kDropQueued) {}
};

/// A slot with a buffer that keeps its capacity from use to use.
struct Numbers {
  std::vector<int> values;
};

TEST(WriterThread, ConsumesInPushOrderInAtMostCapacityReusedSlots) {
  std::vector<int> seen;
  std::set<const int*> buffers;  // the slots' buffers the consumer saw
  WriterThread<Numbers> thread(3, [&](Numbers& slot) {
    seen.insert(seen.end(), slot.values.begin(), slot.values.end());
    buffers.insert(slot.values.data());
  });
  for (int i = 0; i < 2000; ++i)
    thread.push([i](Numbers& slot) {
      slot.values.assign(4, i);  // the same size each time: the buffer is reused
      EXPECT_LE(slot.values.capacity(), 4u);
    });
  thread.finish();
  ASSERT_EQ(seen.size(), 8000u);
  for (std::size_t k = 0; k < seen.size(); ++k) ASSERT_EQ(seen[k], static_cast<int>(k / 4)) << k;
  EXPECT_LE(buffers.size(), 3u);
  EXPECT_EQ(thread.queued(), 0u);
  EXPECT_THROW(thread.push([](Numbers&) {}), Error);  // after finish
}

TEST(WriterThread, NeverHoldsMoreThanCapacityJobs) {
  std::promise<void> gate;
  std::shared_future<void> open = gate.get_future().share();
  std::atomic<int> consumed{0};
  WriterThread<Numbers> thread(2, [&](Numbers&) {
    open.wait();  // the consumer is stuck until the gate opens
    ++consumed;
  });
  thread.push([](Numbers&) {});
  thread.push([](Numbers&) {});
  EXPECT_LE(thread.queued(), 2u);
  // A third push waits for a slot: run it on another thread, then open the gate.
  std::atomic<bool> third_done{false};
  std::thread producer([&] {
    thread.push([](Numbers&) {});
    third_done = true;
  });
  EXPECT_LE(thread.queued(), 2u);
  EXPECT_FALSE(third_done);  // both slots are taken until the consumer moves on
  gate.set_value();
  producer.join();
  EXPECT_TRUE(third_done);
  thread.finish();
  EXPECT_EQ(consumed, 3);
}

TEST(WriterThread, TheConsumersErrorReachesTheProducerWithoutAHang) {
  std::vector<int> seen;
  WriterThread<Numbers> thread(2, [&](Numbers& slot) {
    if (slot.values.at(0) == 5) throw Error("disk full at job 5");
    seen.push_back(slot.values[0]);
  });
  // The producer goes on pushing: one of its pushes (or finish) throws the
  // consumer's error; the jobs after the failed one are not consumed.
  bool thrown = false;
  for (int i = 0; i < 1000 && !thrown; ++i) {
    try {
      thread.push([i](Numbers& slot) { slot.values.assign(1, i); });
    } catch (const Error& e) {
      EXPECT_STREQ(e.what(), "disk full at job 5");
      thrown = true;
    }
  }
  try {
    thread.finish();
    EXPECT_TRUE(thrown) << "finish must throw if no push did";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "disk full at job 5");
    thrown = true;
  }
  EXPECT_TRUE(thrown);
  EXPECT_THROW(thread.finish(), Error);  // the same error again
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(WriterThread, AnErrorOfTheLastJobSurfacesAtFinish) {
  WriterThread<Numbers> thread(4, [](Numbers& slot) {
    if (slot.values.empty()) throw std::runtime_error("empty job");
  });
  thread.push([](Numbers& slot) { slot.values.assign(1, 1); });
  thread.push([](Numbers& slot) { slot.values.clear(); });
  EXPECT_THROW(thread.finish(), std::runtime_error);
}

TEST(WriterThread, DestructionDropsQueuedJobsAndJoins) {
  std::promise<void> gate;
  std::shared_future<void> open = gate.get_future().share();
  std::atomic<int> consumed{0};
  {
    WriterThread<Numbers> thread(8, [&](Numbers&) {
      open.wait();
      ++consumed;
    });
    for (int i = 0; i < 8; ++i) thread.push([](Numbers&) {});
    gate.set_value();  // the job being consumed ends; the rest are dropped
  }
  EXPECT_GE(consumed, 0);
  EXPECT_LE(consumed, 8);
}

EventArray eventsFrom(TimeNs t0, int count) {
  EventArray e;
  for (int i = 0; i < count; ++i)
    e.push_back(t0 + 1000 * i, static_cast<std::uint16_t>(i % 32), static_cast<std::uint16_t>(i % 24), i % 3 == 0);
  return e;
}

std::vector<EventLabel> labelsFor(const EventArray& e) {
  std::vector<EventLabel> labels(e.size());
  for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = static_cast<EventLabel>(i % 4);
  return labels;
}

SequenceWriterOptions smallSensor() {
  SequenceWriterOptions o;
  o.width = 32;
  o.height = 24;
  o.t_offset_ns = 0;
  return o;
}

TEST(AsyncSequenceWriter, WritesTheFilesOfSequenceWriter) {
  test::TempDir tmp;
  SequenceWriter direct(tmp.file("direct"), smallSensor());
  AsyncSequenceWriter async(tmp.file("async"), smallSensor(), 2);
  cv::Mat frame(24, 32, CV_8UC1), depth(24, 32, CV_32FC1), flow(24, 32, CV_32FC2);
  for (int k = 0; k < 20; ++k) {
    const EventArray e = eventsFrom(1'000'000 * k, 50 + k);
    direct.appendEvents(e, labelsFor(e));
    async.appendEvents(e, labelsFor(e));
    if (k % 5 == 0) {
      cv::randu(frame, 0, 255);
      cv::randu(depth, 0.5f, 3.0f);
      cv::randu(flow, -10.0f, 10.0f);
      const TimeNs t = 1'000'000 * k + 500;
      EXPECT_EQ(direct.appendFrame(t, frame), async.appendFrame(t, frame));
      direct.appendDepth(direct.frameCount() - 1, t, depth, flow);
      async.appendDepth(async.frameCount() - 1, t, depth, flow);
      frame.setTo(0);  // the writer copied the images: changing them now changes no file
      depth.setTo(0);
    }
  }
  EXPECT_EQ(direct.eventCount(), async.eventCount());
  const auto files = direct.close();
  const auto async_files = async.close();
  ASSERT_EQ(files.size(), async_files.size());
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string name = fs::relative(files[i], tmp.file("direct")).string();
    EXPECT_EQ(name, fs::relative(async_files[i], tmp.file("async")).string());
    EXPECT_EQ(io::readFile(files[i]), io::readFile(async_files[i])) << name;
  }
  for (const char* f : {"images/frame_00000000.png", "images/frame_00000003.png", "truth/depth/depth_00000003.exr"})
    EXPECT_EQ(io::readFile(tmp.file(std::string("direct/") + f)), io::readFile(tmp.file(std::string("async/") + f)))
        << f;
}

TEST(AsyncSequenceWriter, AFailedWriteSurfacesAndCompletesNoEventFile) {
  test::TempDir tmp;
  bool thrown = false;
  {
    AsyncSequenceWriter async(tmp.file("s"), smallSensor(), 2);
    try {
      const EventArray late = eventsFrom(5'000'000, 10);
      async.appendEvents(late, labelsFor(late));
      const EventArray early = eventsFrom(1'000'000, 10);  // times decrease: events.h5 refuses them
      for (int k = 0; k < 100; ++k) async.appendEvents(early, labelsFor(early));
      async.close();
    } catch (const Error&) {
      thrown = true;
    }
  }
  EXPECT_TRUE(thrown);
  EXPECT_FALSE(fs::exists(tmp.file("s/events.h5")));
  EXPECT_FALSE(fs::exists(tmp.file("s/truth/event_labels.bin")));
}

TEST(AsyncSequenceWriter, ChecksItsArgumentsAtOnce) {
  test::TempDir tmp;
  SequenceWriterOptions o = smallSensor();
  o.frames = false;
  AsyncSequenceWriter async(tmp.file("s"), o);
  const EventArray e = eventsFrom(0, 3);
  EXPECT_THROW(async.appendEvents(e, std::vector<EventLabel>(2)), Error);
  EXPECT_THROW(async.appendFrame(0, cv::Mat(24, 32, CV_8UC1, cv::Scalar(0))), Error);
}

}  // namespace
}  // namespace evio::simulator
