// EventH5Writer: streams events into the DSEC layout (see events_h5.h).

#include <algorithm>
#include <cstdio>
#include <limits>
#include <vector>

#include "events_h5_hdf5.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/options.h"

namespace evio::io {

namespace {
constexpr std::int64_t kMaxU32 = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t kMsChunk = 8192;  // /ms_to_idx entries per chunk (8.2 s)
// Longest span after t_offset the writer accepts: one day. /ms_to_idx grows by
// one entry per millisecond, so a single absurd timestamp must not become a
// file of terabytes.
constexpr std::int64_t kMaxSpanUs = std::int64_t{24} * 3600 * 1'000'000;
}  // namespace

void EventH5Options::validate() const {
  requireInRange("compression_level", compression_level, 0, 9);
  requireInRange("chunk_events", static_cast<double>(chunk_events), 1, 1 << 24);
  requireField(t_type == "auto" || t_type == "uint32" || t_type == "int64", "t_type",
               "must be auto, uint32 or int64 (got '" + t_type + "')");
  requireInRange("width", width, 0, 65536);
  requireInRange("height", height, 0, 65536);
  requireField((width == 0) == (height == 0), "width",
               "width and height must both be given or both be 0");
}

struct EventH5Writer::Impl {
  std::string path;
  std::string tmp;
  EventH5Options opt;
  bool offset_known = false;
  std::int64_t t_offset_us = 0;
  bool wide = false;  // /events/t stored as int64
  bool closed = false;
  bool committed = false;
  bool failed = false;  // a write failed: the file is incomplete

  // Declared first so that it is closed last.
  h5::Handle file;
  h5::Handle t, x, y, p, ms;

  // One chunk of events waiting to be written (relative µs time).
  std::vector<std::int64_t> buf_r;
  std::vector<std::uint16_t> buf_x, buf_y;
  std::vector<std::uint8_t> buf_p;
  std::vector<std::uint32_t> stage_u32;
  std::vector<std::uint64_t> ms_pending;

  std::uint64_t n_written = 0;  // events in the file
  std::uint64_t n_total = 0;    // events appended (file + buffer)
  std::uint64_t ms_written = 0;
  std::int64_t next_ms = 0;  // next /ms_to_idx entry to emit
  TimeNs last_t_ns = std::numeric_limits<TimeNs>::min();

  h5::Handle create(const char* name, hid_t file_type, std::uint64_t chunk) {
    const hsize_t dims[1] = {0};
    const hsize_t max_dims[1] = {H5S_UNLIMITED};
    h5::Handle space = h5::dataspace(
        h5::check(H5Screate_simple(1, dims, max_dims), path, name, "cannot create dataspace"));
    h5::Handle dcpl = h5::plist(h5::check(H5Pcreate(H5P_DATASET_CREATE), path, name, "plist"));
    const hsize_t chunk_dims[1] = {static_cast<hsize_t>(chunk)};
    h5::checkStatus(H5Pset_chunk(dcpl.get(), 1, chunk_dims), path, name, "cannot set chunk size");
    if (opt.compression_level > 0) {
      h5::checkStatus(H5Pset_shuffle(dcpl.get()), path, name, "shuffle filter unavailable");
      h5::checkStatus(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(opt.compression_level)),
                      path, name, "gzip filter unavailable");
    }
    if (opt.checksum)
      h5::checkStatus(H5Pset_fletcher32(dcpl.get()), path, name, "checksum filter unavailable");
    h5::checkStatus(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), path, name, "fill time");
    // No modification times in object headers: same events => byte-identical file.
    h5::checkStatus(H5Pset_obj_track_times(dcpl.get(), false), path, name, "track times");
    return h5::dataset(h5::check(H5Dcreate2(file.get(), name, file_type, space.get(), H5P_DEFAULT,
                                            dcpl.get(), H5P_DEFAULT),
                                 path, name, "cannot create dataset"));
  }

  void appendTo(const h5::Handle& ds, hid_t mem_type, const void* data, std::uint64_t old_size,
                std::uint64_t count, const char* name) {
    if (count == 0) return;
    const hsize_t new_size[1] = {static_cast<hsize_t>(old_size + count)};
    h5::checkStatus(H5Dset_extent(ds.get(), new_size), path, name, "cannot extend dataset");
    h5::Handle fspace =
        h5::dataspace(h5::check(H5Dget_space(ds.get()), path, name, "cannot get dataspace"));
    h5::selectRange(fspace.get(), old_size, count, path, name);
    h5::Handle mspace = h5::simpleSpace(count, path, name);
    h5::checkStatus(H5Dwrite(ds.get(), mem_type, mspace.get(), fspace.get(), H5P_DEFAULT, data),
                    path, name, "write failed");
  }

  void flushEvents() {
    const std::uint64_t m = buf_r.size();
    if (m == 0) return;
    if (wide) {
      appendTo(t, H5T_NATIVE_INT64, buf_r.data(), n_written, m, "/events/t");
    } else {
      stage_u32.resize(m);
      for (std::uint64_t i = 0; i < m; ++i) stage_u32[i] = static_cast<std::uint32_t>(buf_r[i]);
      appendTo(t, H5T_NATIVE_UINT32, stage_u32.data(), n_written, m, "/events/t");
    }
    appendTo(x, H5T_NATIVE_UINT16, buf_x.data(), n_written, m, "/events/x");
    appendTo(y, H5T_NATIVE_UINT16, buf_y.data(), n_written, m, "/events/y");
    appendTo(p, H5T_NATIVE_UINT8, buf_p.data(), n_written, m, "/events/p");
    n_written += m;
    buf_r.clear();
    buf_x.clear();
    buf_y.clear();
    buf_p.clear();
  }

  void flushMs() {
    appendTo(ms, H5T_NATIVE_UINT64, ms_pending.data(), ms_written, ms_pending.size(), "/ms_to_idx");
    ms_written += ms_pending.size();
    ms_pending.clear();
  }

  void pushMs(std::uint64_t index) {
    ms_pending.push_back(index);
    ++next_ms;
    if (ms_pending.size() >= kMsChunk) flushMs();
  }

  // Rewrites the uint32 /events/t written so far as int64, chunk by chunk.
  void widen() {
    h5::Handle wide_t = create("/events/t_int64", H5T_STD_I64LE, opt.chunk_events);
    std::vector<std::int64_t> block;
    h5::Handle fspace =
        h5::dataspace(h5::check(H5Dget_space(t.get()), path, "/events/t", "cannot get dataspace"));
    for (std::uint64_t b = 0; b < n_written; b += opt.chunk_events) {
      const std::uint64_t m = std::min<std::uint64_t>(opt.chunk_events, n_written - b);
      stage_u32.resize(m);
      block.resize(m);
      h5::selectRange(fspace.get(), b, m, path, "/events/t");
      h5::Handle mspace = h5::simpleSpace(m, path, "/events/t");
      h5::checkStatus(H5Dread(t.get(), H5T_NATIVE_UINT32, mspace.get(), fspace.get(), H5P_DEFAULT,
                              stage_u32.data()),
                      path, "/events/t", "cannot read back while widening to int64");
      std::copy(stage_u32.begin(), stage_u32.end(), block.begin());
      appendTo(wide_t, H5T_NATIVE_INT64, block.data(), b, m, "/events/t");
    }
    t.reset();
    h5::checkStatus(H5Ldelete(file.get(), "/events/t", H5P_DEFAULT), path, "/events/t",
                    "cannot replace the uint32 dataset");
    h5::checkStatus(
        H5Lmove(file.get(), "/events/t_int64", file.get(), "/events/t", H5P_DEFAULT, H5P_DEFAULT),
        path, "/events/t", "cannot rename the int64 dataset");
    t = std::move(wide_t);
    wide = true;
  }

  void writeAttribute(const char* name, int value) {
    h5::Handle space = h5::dataspace(h5::check(H5Screate(H5S_SCALAR), path, name, "dataspace"));
    h5::Handle attr = h5::attribute(h5::check(
        H5Acreate2(file.get(), name, H5T_STD_U32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), path,
        name, "cannot create attribute"));
    const std::uint32_t v = static_cast<std::uint32_t>(value);
    h5::checkStatus(H5Awrite(attr.get(), H5T_NATIVE_UINT32, &v), path, name, "cannot write");
  }

  [[noreturn]] void reject(std::string_view field, const std::string& message) const {
    throw Error::inField(path, 0, field, "append: " + message);
  }

  void append(const EventArray& ev) {
    if (closed) throw Error::inFile(path, 0, "append after close()");
    if (failed) throw Error::inFile(path, 0, "append after an earlier write failed");
    const std::size_t n = ev.size();
    if (n == 0) return;
    const std::vector<TimeNs>& ts = ev.t();

    // Validate everything before changing any state.
    if (ts[0] < last_t_ns)
      reject("/events/t", "time goes backwards at event 0 of the appended events (t_ns " +
                              std::to_string(ts[0]) + " < previous " + std::to_string(last_t_ns) +
                              ")");
    for (std::size_t i = 1; i < n; ++i)
      if (ts[i] < ts[i - 1])
        reject("/events/t", "time goes backwards at event " + std::to_string(i) +
                                " of the appended events (t_ns " + std::to_string(ts[i]) + " < " +
                                std::to_string(ts[i - 1]) + ")");
    const std::int64_t offset = offset_known ? t_offset_us : h5::floorDiv1000(ts[0]);
    if (h5::floorDiv1000(ts[0]) < offset)
      reject("/events/t", "event 0 (t_ns " + std::to_string(ts[0]) + ") is before t_offset (" +
                              std::to_string(offset) + " us)");
    const std::int64_t max_rel = h5::floorDiv1000(ts[n - 1]) - offset;
    if (max_rel > kMaxSpanUs)
      reject("/events/t", "event at " + std::to_string(max_rel) +
                              " us after t_offset: spans beyond one day are not supported");
    if (opt.t_type == "uint32" && max_rel > kMaxU32)
      reject("/events/t", "event at " + std::to_string(max_rel) +
                              " us after t_offset does not fit t_type uint32");
    if (opt.width > 0) {
      for (std::size_t i = 0; i < n; ++i)
        if (ev.x()[i] >= opt.width || ev.y()[i] >= opt.height)
          reject("/events/x", "pixel (" + std::to_string(ev.x()[i]) + ", " +
                                  std::to_string(ev.y()[i]) + ") of event " + std::to_string(i) +
                                  " is outside the " + std::to_string(opt.width) + "x" +
                                  std::to_string(opt.height) + " sensor");
    }
    for (std::size_t i = 0; i < n; ++i)
      if (ev.p()[i] > 1)
        reject("/events/p", "polarity of event " + std::to_string(i) + " is not 0 or 1");

    try {
      store(ev, offset, max_rel);
    } catch (...) {
      failed = true;
      throw;
    }
  }

  void store(const EventArray& ev, std::int64_t offset, std::int64_t max_rel) {
    const std::size_t n = ev.size();
    const std::vector<TimeNs>& ts = ev.t();
    offset_known = true;
    t_offset_us = offset;
    if (!wide && max_rel > kMaxU32) widen();

    const std::uint64_t chunk = opt.chunk_events;
    std::size_t done = 0;
    while (done < n) {
      const std::size_t m = static_cast<std::size_t>(
          std::min<std::uint64_t>(n - done, chunk - static_cast<std::uint64_t>(buf_r.size())));
      const std::size_t base = buf_r.size();
      buf_r.resize(base + m);
      for (std::size_t i = 0; i < m; ++i)
        buf_r[base + i] = h5::floorDiv1000(ts[done + i]) - t_offset_us;
      buf_x.insert(buf_x.end(), ev.x().begin() + static_cast<std::ptrdiff_t>(done),
                   ev.x().begin() + static_cast<std::ptrdiff_t>(done + m));
      buf_y.insert(buf_y.end(), ev.y().begin() + static_cast<std::ptrdiff_t>(done),
                   ev.y().begin() + static_cast<std::ptrdiff_t>(done + m));
      buf_p.insert(buf_p.end(), ev.p().begin() + static_cast<std::ptrdiff_t>(done),
                   ev.p().begin() + static_cast<std::ptrdiff_t>(done + m));
      // /ms_to_idx[k] = index of the first event with relative time >= k ms.
      for (std::size_t i = 0; i < m; ++i) {
        const std::int64_t r = buf_r[base + i];
        while (next_ms * 1000 <= r) pushMs(n_total + i);
      }
      n_total += m;
      done += m;
      if (buf_r.size() == chunk) flushEvents();
    }
    last_t_ns = ts[n - 1];
  }

  void close() {
    if (closed) throw Error::inFile(path, 0, "close() called twice");
    if (failed) throw Error::inFile(path, 0, "close() after an earlier write failed");
    closed = true;
    flushEvents();
    pushMs(n_total);  // the entry after the last event's millisecond: all events
    flushMs();

    h5::Handle space =
        h5::dataspace(h5::check(H5Screate(H5S_SCALAR), path, "/t_offset", "dataspace"));
    h5::Handle dcpl = h5::plist(h5::check(H5Pcreate(H5P_DATASET_CREATE), path, "/t_offset", "plist"));
    h5::checkStatus(H5Pset_obj_track_times(dcpl.get(), false), path, "/t_offset", "track times");
    h5::Handle ds = h5::dataset(h5::check(H5Dcreate2(file.get(), "/t_offset", H5T_STD_I64LE,
                                                     space.get(), H5P_DEFAULT, dcpl.get(),
                                                     H5P_DEFAULT),
                                          path, "/t_offset", "cannot create dataset"));
    h5::checkStatus(
        H5Dwrite(ds.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, &t_offset_us), path,
        "/t_offset", "write failed");
    ds.reset();
    if (opt.width > 0) {
      writeAttribute("width", opt.width);
      writeAttribute("height", opt.height);
    }
    bool ok = t.reset() && x.reset() && y.reset() && p.reset() && ms.reset();
    ok = file.reset() && ok;
    if (!ok) h5::fail(path, "", "cannot finish writing the file (disk full?)");
    renameFile(tmp, path);
    committed = true;
  }

  void discard() {
    t.reset();
    x.reset();
    y.reset();
    p.reset();
    ms.reset();
    file.reset();
    if (!committed) std::remove(tmp.c_str());
  }
};

EventH5Writer::EventH5Writer(std::string path, const EventH5Options& options,
                             std::optional<TimeNs> t_offset_ns)
    : impl_(std::make_unique<Impl>()) {
  h5::QuietErrors quiet;
  Impl& w = *impl_;
  w.path = std::move(path);
  try {
    options.validate();
  } catch (const Error& e) {
    throw Error::inFile(w.path, 0, std::string("writer options: ") + e.what());
  }
  w.opt = options;
  w.wide = options.t_type == "int64";
  if (t_offset_ns) {
    w.offset_known = true;
    w.t_offset_us = h5::floorDiv1000(*t_offset_ns);
  }
  w.tmp = temporaryPathFor(w.path);
  try {
    w.file = h5::file(h5::check(H5Fcreate(w.tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                                w.path, "", "cannot create file"));
    h5::Handle gcpl = h5::plist(h5::check(H5Pcreate(H5P_GROUP_CREATE), w.path, "/events", "plist"));
    h5::checkStatus(H5Pset_obj_track_times(gcpl.get(), false), w.path, "/events", "track times");
    h5::Handle g = h5::group(h5::check(
        H5Gcreate2(w.file.get(), "/events", H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), w.path,
        "/events", "cannot create group"));
    w.t = w.create("/events/t", w.wide ? H5T_STD_I64LE : H5T_STD_U32LE, options.chunk_events);
    w.x = w.create("/events/x", H5T_STD_U16LE, options.chunk_events);
    w.y = w.create("/events/y", H5T_STD_U16LE, options.chunk_events);
    w.p = w.create("/events/p", H5T_STD_U8LE, options.chunk_events);
    w.ms = w.create("/ms_to_idx", H5T_STD_U64LE, kMsChunk);
  } catch (...) {
    w.discard();
    throw;
  }
  const std::size_t chunk = static_cast<std::size_t>(options.chunk_events);
  w.buf_r.reserve(chunk);
  w.buf_x.reserve(chunk);
  w.buf_y.reserve(chunk);
  w.buf_p.reserve(chunk);
}

EventH5Writer::~EventH5Writer() {
  h5::QuietErrors quiet;
  if (impl_) impl_->discard();
  impl_.reset();
}

void EventH5Writer::append(const EventArray& events) {
  h5::QuietErrors quiet;
  impl_->append(events);
}

void EventH5Writer::close() {
  h5::QuietErrors quiet;
  try {
    impl_->close();
  } catch (...) {
    impl_->discard();
    throw;
  }
}

std::uint64_t EventH5Writer::size() const { return impl_->n_total; }
const std::string& EventH5Writer::path() const { return impl_->path; }

void writeEventsH5(const std::string& path, const EventArray& events,
                   const EventH5Options& options) {
  EventH5Writer writer(path, options);
  writer.append(events);
  writer.close();
}

}  // namespace evio::io
