// evio's own writer and reader together, and the export's option checks.
// (Bags written independently of evio are tested in bags_test.py.)
#include "evio/bags/bag_export.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "evio/bags/bag_import.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/imu_txt.h"
#include "temp_dir.h"

namespace evio::bags {
namespace {

namespace fs = std::filesystem;

TEST(BagExportOptions, RangesAreChecked) {
  BagExportOptions o;
  EXPECT_NO_THROW(o.validate());
  o.compression = "gzip";
  EXPECT_THROW(o.validate(), Error);
  o = {};
  o.event_window_s = 0.0;
  EXPECT_THROW(o.validate(), Error);
  o.event_window_s = 1.5;
  EXPECT_THROW(o.validate(), Error);
  o = {};
  o.max_events_per_message = 0;
  EXPECT_THROW(o.validate(), Error);
  o.max_events_per_message = 10'000'001;
  EXPECT_THROW(o.validate(), Error);
}

/// Events at t = 0 (ROS cannot record at 0: the bag records at 1 ns, the
/// stamp stays 0) cut into messages by window and by count.
TEST(BagExport, WindowsCountsAndTimeZero) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  fs::create_directories(seq);
  EventArray events;
  for (int i = 0; i < 25; ++i) events.push_back(TimeNs{i} * 100'000, static_cast<std::uint16_t>(i), 3, i % 2 == 0);
  io::writeEventsText(seq + "/events.txt", events);
  io::writeImuText(seq + "/imu.txt", {{0, Vec3(1, 2, 3), Vec3(4, 5, 6)}, {1, Vec3(7, 8, 9), Vec3(1, 2, 3)}});

  // A message spans less than event_window_s from its first event and holds
  // at most max_events_per_message events (one every 0.1 ms here).
  BagExportOptions options;
  options.event_window_s = 0.001;      // 10 events would fit ...
  options.max_events_per_message = 4;  // ... but at most 4: 4 x 6 + 1
  EXPECT_EQ(exportBag(seq, dir.file("count.bag"), options).event_messages, 7u);
  options.event_window_s = 0.00025;  // t - t_first < 0.25 ms: 3 events, 3 x 8 + 1
  options.max_events_per_message = 100;
  const auto s = exportBag(seq, dir.file("a.bag"), options);
  EXPECT_EQ(s.events, 25u);
  EXPECT_EQ(s.event_messages, 9u);
  EXPECT_EQ(s.imu_samples, 2u);
  EXPECT_EQ(s.width, 25);  // from the events: largest x + 1
  EXPECT_FALSE(s.camera_info);

  const std::string back = dir.file("back");
  fs::create_directories(back);
  const auto r = importBag(dir.file("a.bag"), back);
  EXPECT_EQ(r.events, 25u);
  EXPECT_EQ(r.event_messages, 9u);
  EXPECT_EQ(io::readFile(back + "/events.txt"), io::readFile(seq + "/events.txt"));
  EXPECT_EQ(io::readFile(back + "/imu.txt"), io::readFile(seq + "/imu.txt"));
}

/// --events both: events.txt exact, events.h5 floored to µs with the sensor size.
TEST(BagImport, EventsAsHdf5Too) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  fs::create_directories(seq);
  EventArray events;
  for (int i = 0; i < 30; ++i)
    events.push_back(TimeNs{1'000'000'000} + TimeNs{i} * 123'457, static_cast<std::uint16_t>(i), 7, i % 3 == 0);
  io::writeEventsText(seq + "/events.txt", events);
  io::writeCalibTxt(seq + "/calib.txt", io::CalibTxt{Vec4(200, 200, 120, 90), VecX()});
  exportBag(seq, dir.file("a.bag"));

  const std::string back = dir.file("back");
  fs::create_directories(back);
  BagImportOptions options;
  options.events_format = "both";
  importBag(dir.file("a.bag"), back, options);
  EXPECT_EQ(io::readFile(back + "/events.txt"), io::readFile(seq + "/events.txt"));
  io::EventH5Reader h5(back + "/events.h5");
  EXPECT_EQ(h5.width(), 30);  // the export's sensor size: the events' largest x + 1
  EXPECT_EQ(h5.height(), 8);
  EventArray read;
  h5.read(0, h5.size(), read);
  ASSERT_EQ(read.size(), events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(read.t()[i], events.t()[i] / 1000 * 1000);  // floored to the µs
    EXPECT_EQ(read[i].x, events[i].x);
    EXPECT_EQ(read[i].positive, events[i].positive);
  }
  options.events_format = "xml";
  EXPECT_THROW(importBag(dir.file("a.bag"), back, options), Error);
}

TEST(BagExport, NegativeTimeAndEmptyFolderAreErrors) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  fs::create_directories(seq);
  EXPECT_THROW(exportBag(seq, dir.file("a.bag")), Error);  // nothing to export
  io::writeImuText(seq + "/imu.txt", {{-5, Vec3(1, 2, 3), Vec3(4, 5, 6)}});
  try {
    exportBag(seq, dir.file("a.bag"));
    FAIL() << "a negative time was exported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be negative"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/dvs/imu"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.file("a.bag")));
  for (const auto& entry : fs::directory_iterator(dir.path()))  // no temporary left
    EXPECT_EQ(entry.path().filename(), "seq");
}

}  // namespace
}  // namespace evio::bags
