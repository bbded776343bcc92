#include "evio/core/io/events_h5.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <fstream>
#include <limits>

#include "evio/core/error.h"
#include "evio/core/io/events_h5_raw.h"
#include "evio/core/random_stream.h"
#include "error_of.h"
#include "temp_dir.h"

namespace evio::io {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;

/// Sorted random events: exponential gaps at `rate_hz` (some gaps exactly 0),
/// uniform pixels and polarity, times with sub-µs parts.
EventArray randomEvents(std::uint64_t seed, std::size_t n, TimeNs t0_ns, double rate_hz) {
  RandomStream rng(seed, "events_h5_test");
  EventArray ev;
  ev.reserve(n);
  TimeNs t = t0_ns;
  for (std::size_t i = 0; i < n; ++i) {
    if (!rng.bernoulli(0.05)) t += static_cast<TimeNs>(std::llround(rng.exponential(rate_hz) * 1e9));
    ev.push_back(t, static_cast<std::uint16_t>(rng.uniformInt(kWidth)),
                 static_cast<std::uint16_t>(rng.uniformInt(kHeight)), rng.bernoulli(0.5));
  }
  return ev;
}

/// floor(t / 1 µs) in ns, exact for any sign.
TimeNs floorUs(TimeNs t) {
  TimeNs q = t / 1000;
  if (t % 1000 < 0) --q;
  return q * 1000;
}

/// What the file stores: times floored to the µs.
EventArray atUsResolution(const EventArray& ev) {
  EventArray out = ev;
  for (TimeNs& t : out.t()) t = floorUs(t);
  return out;
}

/// The events of `ev` with t0 <= t < t1, by linear scan.
EventArray bruteForceWindow(const EventArray& ev, TimeNs t0, TimeNs t1) {
  EventArray out;
  for (std::size_t i = 0; i < ev.size(); ++i)
    if (ev.t()[i] >= t0 && ev.t()[i] < t1) out.push_back(ev[i]);
  return out;
}

EventArray slice(const EventArray& ev, std::size_t begin, std::size_t end) {
  EventArray out = ev;
  out.keepRange(begin, end);
  return out;
}

/// Writes `ev` in pieces of random size so that appends straddle chunks.
void writeInPieces(const std::string& path, const EventArray& ev, const EventH5Options& opt,
                   std::uint64_t seed) {
  RandomStream rng(seed, "pieces");
  EventH5Writer w(path, opt);
  std::size_t i = 0;
  while (i < ev.size()) {
    const std::size_t m = std::min<std::size_t>(ev.size() - i, rng.uniformInt(3000));
    w.append(slice(ev, i, i + m));
    i += m;
  }
  EXPECT_EQ(w.size(), ev.size());
  w.close();
}

using test::errorOf;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

/// A valid DSEC-layout file built dataset by dataset (no attributes, like DSEC).
std::vector<h5raw::Dataset> rawLayout(std::vector<std::int64_t> t) {
  const std::size_t n = t.size();
  std::vector<std::int64_t> ms;
  const std::int64_t last = n ? t.back() : 0;
  for (std::int64_t k = 0; k <= last / 1000 + 1; ++k)
    ms.push_back(std::lower_bound(t.begin(), t.end(), k * 1000) - t.begin());
  std::vector<std::int64_t> x(n), y(n), p(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<std::int64_t>(i % 7);
    y[i] = static_cast<std::int64_t>(i % 5);
    p[i] = static_cast<std::int64_t>(i % 2);
  }
  return {{"/events/t", h5raw::Type::kUint32, std::move(t), false},
          {"/events/x", h5raw::Type::kUint16, x, false},
          {"/events/y", h5raw::Type::kUint16, y, false},
          {"/events/p", h5raw::Type::kUint8, p, false},
          {"/ms_to_idx", h5raw::Type::kUint64, ms, false},
          {"/t_offset", h5raw::Type::kInt64, {5'000'000}, true}};
}

h5raw::Dataset& find(std::vector<h5raw::Dataset>& layout, const std::string& name) {
  return *std::find_if(layout.begin(), layout.end(), [&](const auto& d) { return d.name == name; });
}

TEST(EventsH5, RoundTripIsExactAtMicrosecondsWithAndWithoutCompression) {
  test::TempDir dir;
  // Start at a Unix-epoch time and at a negative time (floor, not truncation).
  for (const TimeNs t0 : {TimeNs{1'700'000'000'123'456'789}, TimeNs{-2'000'000'500}}) {
    const EventArray ev = randomEvents(1, 60'000, t0, 2e6);
    for (const int level : {0, 1, 6}) {
      EventH5Options opt;
      opt.compression_level = level;
      opt.chunk_events = 4096;
      const std::string path = dir.file("ev_" + std::to_string(level) + ".h5");
      writeInPieces(path, ev, opt, 2);
      EXPECT_EQ(h5raw::datasetType(path, "/events/t"), "uint32");
      const EventArray back = readEventsH5(path);
      const EventArray expected = atUsResolution(ev);
      ASSERT_EQ(back.size(), ev.size());
      EXPECT_TRUE(back == expected) << "level " << level;
      EventH5Reader r(path);
      EXPECT_EQ(r.tOffsetNs(), floorUs(ev.t().front()));
      EXPECT_EQ(r.tFirstNs(), expected.t().front());
      EXPECT_EQ(r.tLastNs(), expected.t().back());
      EXPECT_EQ(r.width(), 0);
    }
  }
}

TEST(EventsH5, MsToIdxFollowsTheDsecDefinition) {
  test::TempDir dir;
  const EventArray ev = randomEvents(3, 20'000, 42'000'777, 1e6);
  const std::string path = dir.file("ev.h5");
  EventH5Options opt;
  opt.chunk_events = 1000;
  writeInPieces(path, ev, opt, 4);
  const std::vector<std::int64_t> ms = h5raw::readDataset(path, "/ms_to_idx");
  const std::vector<std::int64_t> t = h5raw::readDataset(path, "/events/t");
  EXPECT_EQ(h5raw::readDataset(path, "/t_offset"),
            std::vector<std::int64_t>{floorUs(ev.t().front()) / 1000});
  EXPECT_EQ(h5raw::datasetType(path, "/ms_to_idx"), "uint64");
  ASSERT_EQ(t.size(), ev.size());
  ASSERT_EQ(ms.size(), static_cast<std::size_t>(t.back() / 1000 + 2));
  for (std::size_t k = 0; k < ms.size(); ++k) {
    const auto first = std::lower_bound(t.begin(), t.end(), static_cast<std::int64_t>(k) * 1000);
    ASSERT_EQ(ms[k], first - t.begin()) << "k = " << k;
  }
  EXPECT_EQ(ms.back(), static_cast<std::int64_t>(ev.size()));
}

TEST(EventsH5, ReadWindowEqualsBruteForceFilter) {
  test::TempDir dir;
  const EventArray ev = atUsResolution(randomEvents(5, 30'000, 7'000'000'400, 1e6));
  const std::string path = dir.file("ev.h5");
  EventH5Options opt;
  opt.chunk_events = 2048;
  writeEventsH5(path, ev, opt);
  EventH5Reader r(path);
  const TimeNs first = ev.t().front(), last = ev.t().back();
  std::vector<std::pair<TimeNs, TimeNs>> windows = {
      {first, last + 1},         {first, last},          {first - 5'000'000, first},
      {last + 1, last + 10'000}, {first + 10, first + 10}, {first + 500'000, first + 100},
      {std::numeric_limits<TimeNs>::min(), std::numeric_limits<TimeNs>::max()},
      {first - 1, first + 1},    {last, last + 1},       {ev.t()[777], ev.t()[778]},
      {ev.t()[777] + 1, ev.t()[9000] - 1}};
  RandomStream rng(6, "windows");
  for (int i = 0; i < 300; ++i) {
    const double span = static_cast<double>(last - first);
    const TimeNs a = first + static_cast<TimeNs>(rng.uniform(-0.05, 1.05) * span);
    const TimeNs len = static_cast<TimeNs>(rng.uniform() * rng.uniform() * 0.2 * span);
    windows.emplace_back(a, a + len);
    const std::size_t j = rng.uniformInt(ev.size());  // edges exactly on event times
    windows.emplace_back(ev.t()[j], ev.t()[std::min(ev.size() - 1, j + rng.uniformInt(3000))]);
  }
  EventArray got;
  for (const auto& [t0, t1] : windows) {
    r.readWindow(t0, t1, got);
    const EventArray want = bruteForceWindow(ev, t0, t1);
    ASSERT_EQ(got.size(), want.size()) << "[" << t0 << ", " << t1 << ")";
    ASSERT_TRUE(got == want) << "[" << t0 << ", " << t1 << ")";
  }
}

TEST(EventsH5, StreamingNextConcatenatesToTheWhole) {
  test::TempDir dir;
  const EventArray ev = atUsResolution(randomEvents(7, 25'000, 0, 5e5));
  const std::string path = dir.file("ev.h5");
  EventH5Options opt;
  opt.chunk_events = 3000;
  opt.compression_level = 3;
  writeEventsH5(path, ev, opt);
  EventH5Reader r(path);
  for (const std::size_t max_events : {std::size_t{1}, std::size_t{7}, std::size_t{2999},
                                       std::size_t{3000}, std::size_t{1} << 22}) {
    r.seek(0);
    EventArray all, part;
    std::size_t calls = 0;
    while (r.next(part, max_events)) {
      ASSERT_LE(part.size(), max_events);
      ASSERT_FALSE(part.empty());
      all.append(part);
      ++calls;
    }
    EXPECT_TRUE(part.empty());
    EXPECT_FALSE(r.next(part, max_events));
    EXPECT_EQ(calls, (ev.size() + max_events - 1) / max_events);
    EXPECT_TRUE(all == ev) << "max_events " << max_events;
  }
  r.seek(12'345);
  EventArray part;
  ASSERT_TRUE(r.next(part, 10));
  EXPECT_TRUE(part == slice(ev, 12'345, 12'355));
  EXPECT_THROW(r.seek(ev.size() + 1), Error);
  EXPECT_THROW(r.next(part, 0), Error);
}

TEST(EventsH5, ReadByIndexRange) {
  test::TempDir dir;
  const EventArray ev = atUsResolution(randomEvents(8, 10'000, 123, 1e6));
  const std::string path = dir.file("ev.h5");
  writeEventsH5(path, ev);
  EventH5Reader r(path);
  EventArray out;
  r.read(0, 0, out);
  EXPECT_TRUE(out.empty());
  r.read(4321, 1000, out);
  EXPECT_TRUE(out == slice(ev, 4321, 5321));
  r.read(ev.size() - 1, 1, out);
  EXPECT_TRUE(out == slice(ev, ev.size() - 1, ev.size()));
  EXPECT_THROW(r.read(ev.size() - 10, 11, out), Error);
  EXPECT_THROW(r.read(ev.size() + 1, 0, out), Error);
}

TEST(EventsH5, Uint32AndInt64TimesAreBothReadable) {
  test::TempDir dir;
  const EventArray ev = randomEvents(9, 5'000, 1'000'000, 1e6);
  for (const std::string type : {"uint32", "int64"}) {
    EventH5Options opt;
    opt.t_type = type;
    opt.chunk_events = 512;
    const std::string path = dir.file(type + ".h5");
    writeInPieces(path, ev, opt, 10);
    EXPECT_EQ(h5raw::datasetType(path, "/events/t"), type);
    EXPECT_TRUE(readEventsH5(path) == atUsResolution(ev)) << type;
    EventH5Reader r(path);
    EventArray w;
    r.readWindow(ev.t()[100], ev.t()[2000], w);
    EXPECT_TRUE(w == bruteForceWindow(atUsResolution(ev), ev.t()[100], ev.t()[2000])) << type;
    EXPECT_GT(w.size(), 1000u);
  }
  // Any integer type is accepted for /events/t (here int32).
  auto layout = rawLayout({0, 10, 10, 2500, 2501});
  find(layout, "/events/t").type = h5raw::Type::kInt32;
  const std::string path = dir.file("int32.h5");
  h5raw::writeDatasets(path, layout);
  const EventArray back = readEventsH5(path);
  ASSERT_EQ(back.size(), 5u);
  EXPECT_EQ(back.t()[3], (TimeNs{5'000'000} + 2500) * 1000);
}

TEST(EventsH5, AutoTimeTypeWidensToInt64BeyondTheUint32Span) {
  test::TempDir dir;
  EventArray ev = randomEvents(11, 3000, 0, 1e6);
  EventArray late = randomEvents(12, 3000, (TimeNs{1} << 32) * 1000 + 5'000, 1e6);
  EventH5Options opt;
  opt.chunk_events = 256;  // the rewrite copies several chunks
  const std::string path = dir.file("wide.h5");
  {
    EventH5Writer w(path, opt);
    w.append(ev);
    w.append(late);
    w.close();
  }
  ev.append(late);
  EXPECT_EQ(h5raw::datasetType(path, "/events/t"), "int64");
  const EventArray expected = atUsResolution(ev);
  EXPECT_TRUE(readEventsH5(path) == expected);
  EventH5Reader r(path);
  EventArray got;
  r.readWindow(expected.t()[2990], expected.t()[3010], got);
  EXPECT_TRUE(got == bruteForceWindow(expected, expected.t()[2990], expected.t()[3010]));
  EXPECT_GE(got.size(), 15u);

  opt.t_type = "uint32";
  EventH5Writer w(dir.file("narrow.h5"), opt);
  w.append(slice(ev, 0, 3000));
  EXPECT_CONTAINS(errorOf([&] { w.append(late); }), "uint32");
}

TEST(EventsH5, WriterRejectsBadEventsAndStaysUsable) {
  test::TempDir dir;
  const std::string path = dir.file("ev.h5");
  EventH5Options opt;
  opt.width = kWidth;
  opt.height = kHeight;
  EventH5Writer w(path, opt, TimeNs{1'000'000});
  EventArray a;
  a.push_back(2'000'000, 1, 1, true);
  a.push_back(3'000'000, 2, 2, false);
  w.append(a);

  EventArray within;  // decreasing inside one append
  within.push_back(4'000'000, 1, 1, true);
  within.push_back(3'999'999, 1, 1, true);
  EXPECT_CONTAINS(errorOf([&] { w.append(within); }), "event 1");
  EventArray across;  // decreasing across appends
  across.push_back(2'999'999, 1, 1, true);
  EXPECT_CONTAINS(errorOf([&] { w.append(across); }), "backwards");
  EventArray outside;
  outside.push_back(5'000'000, kWidth, 0, true);
  EXPECT_CONTAINS(errorOf([&] { w.append(outside); }), "outside");
  EXPECT_EQ(w.size(), 2u);

  EventArray b;
  b.push_back(3'000'000, 3, 3, true);  // equal time is fine
  w.append(b);
  w.close();
  EXPECT_THROW(w.append(b), Error);
  a.append(b);
  EXPECT_TRUE(readEventsH5(path) == a);
  EventH5Reader r(path);
  EXPECT_EQ(r.width(), kWidth);
  EXPECT_EQ(r.height(), kHeight);
  EXPECT_EQ(r.tOffsetNs(), 1'000'000);

  EventH5Writer w2(dir.file("early.h5"), {}, TimeNs{1'000'000});
  EventArray early;
  early.push_back(999'999, 0, 0, true);
  EXPECT_CONTAINS(errorOf([&] { w2.append(early); }), "before t_offset");

  EventH5Options bad;
  bad.compression_level = 10;
  EXPECT_CONTAINS(errorOf([&] { EventH5Writer w3(dir.file("bad.h5"), bad); }), "compression_level");
  bad = {};
  bad.t_type = "float";
  EXPECT_THROW(EventH5Writer(dir.file("bad.h5"), bad), Error);
}

TEST(EventsH5, WriterDestroyedWithoutCloseLeavesNoFile) {
  test::TempDir dir;
  {
    EventH5Writer w(dir.file("ev.h5"));
    w.append(randomEvents(13, 100'000, 0, 1e6));
  }
  { EventH5Writer w(dir.file("ev2.h5")); }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  EXPECT_THROW(EventH5Writer(dir.file("no/such/dir/ev.h5")), Error);
}

TEST(EventsH5, EmptyFile) {
  test::TempDir dir;
  const std::string path = dir.file("empty.h5");
  writeEventsH5(path, EventArray{});
  EventH5Reader r(path);
  EXPECT_EQ(r.size(), 0u);
  EXPECT_EQ(h5raw::readDataset(path, "/ms_to_idx"), std::vector<std::int64_t>{0});
  EventArray out;
  out.push_back(1, 1, 1, true);
  r.readWindow(-1'000'000, 1'000'000, out);
  EXPECT_TRUE(out.empty());
  EXPECT_FALSE(r.next(out, 10));
  EXPECT_TRUE(readEventsH5(path).empty());
}

TEST(EventsH5, ReadsAFileWithoutAttributesLikeDsec) {
  test::TempDir dir;
  const std::string path = dir.file("dsec.h5");
  h5raw::writeDatasets(path, rawLayout({0, 1, 999, 1000, 1000, 4000}));
  EventH5Reader r(path);
  EXPECT_EQ(r.width(), 0);
  EXPECT_EQ(r.size(), 6u);
  EventArray w;
  r.readWindow(5'000'000'000 + 1'000'000, 5'000'000'000 + 4'000'000, w);
  EXPECT_EQ(w.size(), 2u);
  // The sensor size can be given by the caller; pixels are checked against it.
  EventH5Reader small(path, 5, 5);
  EXPECT_CONTAINS(errorOf([&] { small.read(0, 6, w); }), "/events/x: 5 at index 5");
}

TEST(EventsH5, BadFilesThrowErrorsNamingFileDatasetAndIndex) {
  test::TempDir dir;
  const std::string missing = dir.file("missing.h5");
  EXPECT_CONTAINS(errorOf([&] { readEventsH5(missing); }), missing);

  const std::string text = dir.file("text.h5");
  std::ofstream(text) << "0.000001 1 2 1\n";
  EXPECT_CONTAINS(errorOf([&] { readEventsH5(text); }), "not an HDF5 file");

  const std::string valid = dir.file("valid.h5");
  writeEventsH5(valid, randomEvents(14, 50'000, 0, 1e6));
  const std::string truncated = dir.file("truncated.h5");
  std::filesystem::copy_file(valid, truncated);
  std::filesystem::resize_file(truncated, std::filesystem::file_size(valid) / 2);
  EXPECT_CONTAINS(errorOf([&] { readEventsH5(truncated); }), truncated);

  // Flipped bytes inside chunk data are caught by the per-chunk checksum.
  const std::string corrupt = dir.file("corrupt.h5");
  std::filesystem::copy_file(valid, corrupt);
  {
    std::fstream f(corrupt, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(std::filesystem::file_size(corrupt) / 2));
    f.write("\x5a\xa5\x5a\xa5", 4);
  }
  EXPECT_CONTAINS(errorOf([&] { readEventsH5(corrupt); }), corrupt);

  auto write = [&](const std::string& name, const std::vector<h5raw::Dataset>& layout) {
    const std::string path = dir.file(name);
    h5raw::writeDatasets(path, layout);
    return path;
  };
  const std::vector<std::int64_t> t = {0, 5, 7, 3, 9, 12};
  auto no_x = rawLayout({0, 5, 7, 8});
  no_x.erase(std::remove_if(no_x.begin(), no_x.end(), [](auto& d) { return d.name == "/events/x"; }),
             no_x.end());
  std::string p = write("no_x.h5", no_x);
  std::string msg = errorOf([&] { EventH5Reader r(p); });
  EXPECT_CONTAINS(msg, p);
  EXPECT_CONTAINS(msg, "/events/x: missing dataset");

  auto short_y = rawLayout({0, 5, 7, 8});
  find(short_y, "/events/y").values.pop_back();
  msg = errorOf([&] { EventH5Reader r(write("short_y.h5", short_y)); });
  EXPECT_CONTAINS(msg, "/events/y: has 3 entries but /events/t has 4");

  p = write("decreasing.h5", rawLayout(t));
  msg = errorOf([&] { readEventsH5(p); });
  EXPECT_CONTAINS(msg, p);
  EXPECT_CONTAINS(msg, "/events/t: time decreases at index 3");
  EventH5Reader r(p);  // opening succeeds (first <= last); streaming finds it
  EventArray out;
  msg = errorOf([&] {
    while (r.next(out, 2)) {
    }
  });
  EXPECT_CONTAINS(msg, "index 3");

  auto float_t = rawLayout({0, 5, 7, 8});
  find(float_t, "/events/t").type = h5raw::Type::kFloat64;
  EXPECT_CONTAINS(errorOf([&] { EventH5Reader q(write("float_t.h5", float_t)); }),
                  "/events/t: must be an integer type (got float64)");
  auto signed_x = rawLayout({0, 5, 7, 8});
  find(signed_x, "/events/x").type = h5raw::Type::kInt32;
  EXPECT_CONTAINS(errorOf([&] { EventH5Reader q(write("signed_x.h5", signed_x)); }),
                  "/events/x: must be an unsigned integer");
  auto bad_p = rawLayout({0, 5, 7, 8});
  find(bad_p, "/events/p").values[2] = 2;
  EXPECT_CONTAINS(errorOf([&] { readEventsH5(write("bad_p.h5", bad_p)); }),
                  "/events/p: polarity 2 at index 2");
  auto no_offset = rawLayout({0, 5, 7, 8});
  no_offset.pop_back();
  EXPECT_CONTAINS(errorOf([&] { EventH5Reader q(write("no_offset.h5", no_offset)); }),
                  "/t_offset: missing dataset");
  auto bad_ms = rawLayout({0, 500, 1500, 2500, 3500});
  find(bad_ms, "/ms_to_idx").values[2] = 4;  // should be 3
  EventH5Reader q(write("bad_ms.h5", bad_ms));
  EXPECT_CONTAINS(errorOf([&] { q.readWindow(5'002'000'000, 5'003'000'000, out); }),
                  "/ms_to_idx: entry 2 = 4");
  EXPECT_CONTAINS(errorOf([&] { readEventsH5(valid, 100, 100); }), "outside the sensor width 100");
  EventH5Options sized;
  sized.width = 8;
  sized.height = 8;
  writeEventsH5(dir.file("sized.h5"), EventArray{}, sized);
  EXPECT_CONTAINS(errorOf([&] { EventH5Reader s(dir.file("sized.h5"), 10, 10); }),
                  "file is for a 8x8 sensor");
}

TEST(EventsH5, Hdf5PrintsNothingOnErrors) {
  test::TempDir dir;
  const std::string text = dir.file("text.h5");
  std::ofstream(text) << "not hdf5";
  auto layout = rawLayout({0, 5});
  layout.erase(layout.begin() + 1);
  h5raw::writeDatasets(dir.file("no_x.h5"), layout);
  testing::internal::CaptureStderr();
  EXPECT_THROW(readEventsH5(text), Error);
  EXPECT_THROW(readEventsH5(dir.file("no_x.h5")), Error);
  EXPECT_THROW(h5raw::readDataset(dir.file("no_x.h5"), "/nothing"), Error);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace evio::io
