// EventH5Reader: validated streaming reads of the DSEC layout (see events_h5.h).

#include <algorithm>
#include <filesystem>
#include <limits>
#include <vector>

#include "events_h5_hdf5.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/library_crash_guard.h"

namespace evio::io {

namespace {
constexpr std::uint64_t kBlock = std::uint64_t{1} << 20;  // events per H5Dread
constexpr std::int64_t kMaxUs = std::numeric_limits<std::int64_t>::max() / 1000;
constexpr std::int64_t kMinUs = std::numeric_limits<std::int64_t>::min() / 1000;

std::string str(std::int64_t v) { return std::to_string(v); }
std::string str(std::uint64_t v) { return std::to_string(v); }
}  // namespace

struct EventH5Reader::Impl {
  std::string path;
  // Declared first so that it is closed last.
  h5::Handle file;
  h5::Handle t, x, y, p, ms;
  h5::Handle t_space, x_space, y_space, p_space, ms_space;
  bool t_u32 = false;  // /events/t stored as uint32 (read without conversion)
  std::uint64_t n = 0;
  std::uint64_t ms_len = 0;
  std::int64_t t_offset_us = 0;
  std::int64_t r_first = 0, r_last = 0;  // relative µs of the first and last event
  int width = 0, height = 0;

  std::uint64_t cursor = 0;  // next() position
  bool prev_valid = false;   // prev_r holds the relative time of event cursor - 1
  std::int64_t prev_r = 0;

  std::vector<std::uint32_t> s_u32;
  std::vector<std::int64_t> s_i64;

  [[noreturn]] void bad(std::string_view field, const std::string& message) const {
    throw Error::inField(path, 0, field, message);
  }

  // Opens dataset `name`, sizing its chunk cache to hold two chunks so that
  // reads not aligned to chunks never decompress a chunk twice.
  h5::Handle openDataset(const char* name) {
    const std::string s(name);
    for (std::size_t pos = s.find('/', 1); ; pos = s.find('/', pos + 1)) {
      const std::string prefix = s.substr(0, pos);
      if (H5Lexists(file.get(), prefix.c_str(), H5P_DEFAULT) <= 0) {
        h5::takeHdf5Message();
        bad(name, prefix == s ? "missing dataset" : "missing group " + prefix);
      }
      if (pos == std::string::npos) break;
    }
    h5::Handle ds =
        h5::dataset(h5::check(H5Dopen2(file.get(), name, H5P_DEFAULT), path, name, "not a dataset"));
    h5::Handle dcpl =
        h5::plist(h5::check(H5Dget_create_plist(ds.get()), path, name, "cannot read layout"));
    if (H5Pget_layout(dcpl.get()) != H5D_CHUNKED) return ds;
    hsize_t chunk[H5S_MAX_RANK] = {0};
    if (H5Pget_chunk(dcpl.get(), H5S_MAX_RANK, chunk) != 1) return ds;  // rank is checked later
    h5::Handle type = h5::datatype(h5::check(H5Dget_type(ds.get()), path, name, "no type"));
    const std::size_t chunk_bytes = static_cast<std::size_t>(chunk[0]) * H5Tget_size(type.get());
    const std::size_t cache_bytes = std::max<std::size_t>(std::size_t{1} << 20, 2 * chunk_bytes);
    if (cache_bytes > (std::size_t{1} << 30)) return ds;  // absurd chunk: keep the default
    h5::Handle dapl = h5::plist(h5::check(H5Pcreate(H5P_DATASET_ACCESS), path, name, "plist"));
    // w0 = 0.75 (HDF5's default): with w0 = 1.0, HDF5 1.10.8 keeps every chunk
    // ever touched by random reads in memory (measured: memory grew to the
    // dataset's size whatever the cache size).
    h5::checkStatus(H5Pset_chunk_cache(dapl.get(), 521, cache_bytes, 0.75), path, name, "cache");
    ds.reset();
    return h5::dataset(
        h5::check(H5Dopen2(file.get(), name, dapl.get()), path, name, "cannot open dataset"));
  }

  // Checks class (integer) and rank; returns the 1-D length.
  std::uint64_t integerLength(const h5::Handle& ds, const char* name, h5::Handle& space) {
    h5::Handle type = h5::datatype(h5::check(H5Dget_type(ds.get()), path, name, "no type"));
    if (H5Tget_class(type.get()) != H5T_INTEGER)
      bad(name, "must be an integer type (got " + h5::typeName(type.get()) + ")");
    space = h5::dataspace(h5::check(H5Dget_space(ds.get()), path, name, "no dataspace"));
    if (H5Sget_simple_extent_ndims(space.get()) != 1) bad(name, "must be one-dimensional");
    hsize_t dims[1] = {0};
    H5Sget_simple_extent_dims(space.get(), dims, nullptr);
    return dims[0];
  }

  void requireUnsignedAtMost16(const h5::Handle& ds, const char* name) {
    h5::Handle type = h5::datatype(h5::check(H5Dget_type(ds.get()), path, name, "no type"));
    if (H5Tget_sign(type.get()) != H5T_SGN_NONE || H5Tget_size(type.get()) > 2)
      bad(name, "must be an unsigned integer of at most 16 bits (got " + h5::typeName(type.get()) +
                    ")");
  }

  void readSelection(const h5::Handle& ds, const h5::Handle& space, hid_t mem_type,
                     std::uint64_t begin, std::uint64_t count, void* out, const char* name) {
    h5::selectRange(space.get(), begin, count, path, name);
    h5::Handle mspace = h5::simpleSpace(count, path, name);
    if (H5Dread(ds.get(), mem_type, mspace.get(), space.get(), H5P_DEFAULT, out) < 0)
      h5::fail(path, name,
               "cannot read events " + str(begin) + ".." + str(begin + count - 1) +
                   " (file truncated or corrupt?)");
  }

  std::int64_t readRel(std::uint64_t i) {
    std::int64_t v = 0;
    readSelection(t, t_space, H5T_NATIVE_INT64, i, 1, &v, "/events/t");
    return v;
  }

  std::int64_t readAttribute(const char* name) {
    h5::Handle attr = h5::attribute(
        h5::check(H5Aopen(file.get(), name, H5P_DEFAULT), path, name, "cannot open attribute"));
    h5::Handle type = h5::datatype(h5::check(H5Aget_type(attr.get()), path, name, "no type"));
    if (H5Tget_class(type.get()) != H5T_INTEGER)
      bad(std::string("attribute ") + name, "must be an integer");
    h5::Handle space = h5::dataspace(h5::check(H5Aget_space(attr.get()), path, name, "no space"));
    if (H5Sget_simple_extent_npoints(space.get()) != 1)
      bad(std::string("attribute ") + name, "must hold one value");
    std::int64_t v = 0;
    h5::checkStatus(H5Aread(attr.get(), H5T_NATIVE_INT64, &v), path, name, "cannot read");
    if (v < 1 || v > 65536) bad(std::string("attribute ") + name, "must be in [1, 65536]");
    return v;
  }

  void open(int want_width, int want_height) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      throw Error::inFile(path, 0, "cannot open file (missing or not a regular file)");
    const htri_t is_h5 = H5Fis_hdf5(path.c_str());
    if (is_h5 <= 0) {
      h5::takeHdf5Message();
      throw Error::inFile(path, 0, "not an HDF5 file");
    }
    file = h5::file(h5::check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path, "",
                              "cannot open HDF5 file (truncated or corrupt?)"));
    t = openDataset("/events/t");
    x = openDataset("/events/x");
    y = openDataset("/events/y");
    p = openDataset("/events/p");
    ms = openDataset("/ms_to_idx");
    n = integerLength(t, "/events/t", t_space);
    const std::uint64_t nx = integerLength(x, "/events/x", x_space);
    const std::uint64_t ny = integerLength(y, "/events/y", y_space);
    const std::uint64_t np = integerLength(p, "/events/p", p_space);
    ms_len = integerLength(ms, "/ms_to_idx", ms_space);
    requireUnsignedAtMost16(x, "/events/x");
    requireUnsignedAtMost16(y, "/events/y");
    for (auto [len, name] : {std::pair{nx, "/events/x"}, {ny, "/events/y"}, {np, "/events/p"}})
      if (len != n) bad(name, "has " + str(len) + " entries but /events/t has " + str(n));
    if (ms_len == 0) bad("/ms_to_idx", "is empty");
    {
      h5::Handle type = h5::datatype(h5::check(H5Dget_type(t.get()), path, "/events/t", "type"));
      t_u32 = H5Tget_size(type.get()) == 4 && H5Tget_sign(type.get()) == H5T_SGN_NONE;
    }

    h5::Handle off = openDataset("/t_offset");
    {
      h5::Handle type = h5::datatype(h5::check(H5Dget_type(off.get()), path, "/t_offset", "type"));
      if (H5Tget_class(type.get()) != H5T_INTEGER)
        bad("/t_offset", "must be an integer type (got " + h5::typeName(type.get()) + ")");
      h5::Handle space =
          h5::dataspace(h5::check(H5Dget_space(off.get()), path, "/t_offset", "no dataspace"));
      if (H5Sget_simple_extent_npoints(space.get()) != 1) bad("/t_offset", "must hold one value");
      h5::checkStatus(
          H5Dread(off.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, &t_offset_us), path,
          "/t_offset", "cannot read (file truncated or corrupt?)");
      if (t_offset_us < kMinUs || t_offset_us > kMaxUs)
        bad("/t_offset", "out of range for int64 nanoseconds");
    }

    if (n > 0) {
      r_first = readRel(0);
      r_last = readRel(n - 1);
      if (r_first < 0) bad("/events/t", "negative time " + str(r_first) + " us at index 0");
      if (r_last < r_first)
        bad("/events/t", "time decreases: index " + str(n - 1) + " (" + str(r_last) +
                             " us) is before index 0 (" + str(r_first) + " us)");
      if (r_last > kMaxUs - t_offset_us)
        bad("/events/t", "time at index " + str(n - 1) + " overflows int64 nanoseconds");
    }

    int file_width = 0, file_height = 0;
    const htri_t has_w = H5Aexists(file.get(), "width");
    const htri_t has_h = H5Aexists(file.get(), "height");
    if (has_w > 0 && has_h > 0) {
      file_width = static_cast<int>(readAttribute("width"));
      file_height = static_cast<int>(readAttribute("height"));
    }
    if (want_width > 0) {
      if (file_width > 0 && (file_width != want_width || file_height != want_height))
        throw Error::inFile(path, 0,
                            "file is for a " + std::to_string(file_width) + "x" +
                                std::to_string(file_height) + " sensor, expected " +
                                std::to_string(want_width) + "x" + std::to_string(want_height));
      width = want_width;
      height = want_height;
    } else {
      width = file_width;
      height = file_height;
    }
  }

  // Validates relative times rel[0..m) of events begin..begin+m-1: sorted,
  // after `prev` (the time of event begin-1) when known, within the file's
  // first and last time (which bounds every value once sorted).
  template <class T>
  void checkRel(const T* rel, std::uint64_t m, std::uint64_t begin, bool have_prev,
                std::int64_t prev) const {
    if (m == 0) return;
    const std::int64_t lo = have_prev ? std::max(prev, r_first) : r_first;
    if (static_cast<std::int64_t>(rel[0]) < lo)
      bad("/events/t", "time decreases at index " + str(begin) + " (" +
                           str(static_cast<std::int64_t>(rel[0])) + " us < " + str(lo) +
                           " us before it)");
    unsigned unsorted = 0;
    for (std::uint64_t i = 1; i < m; ++i) unsorted |= static_cast<unsigned>(rel[i] < rel[i - 1]);
    if (unsorted) {
      for (std::uint64_t i = 1; i < m; ++i)
        if (rel[i] < rel[i - 1])
          bad("/events/t", "time decreases at index " + str(begin + i) + " (" +
                               str(static_cast<std::int64_t>(rel[i])) + " us < " +
                               str(static_cast<std::int64_t>(rel[i - 1])) + " us)");
    }
    if (static_cast<std::int64_t>(rel[m - 1]) > r_last)
      bad("/events/t", "time decreases after index " + str(begin + m - 1) + " (" +
                           str(static_cast<std::int64_t>(rel[m - 1])) +
                           " us is after the last event's " + str(r_last) + " us)");
  }

  // Reads relative times of [begin, begin + m) into s_i64, validated.
  const std::int64_t* loadRel(std::uint64_t begin, std::uint64_t m) {
    s_i64.resize(m);
    if (m == 0) return s_i64.data();
    if (t_u32) {
      s_u32.resize(m);
      readSelection(t, t_space, H5T_NATIVE_UINT32, begin, m, s_u32.data(), "/events/t");
      std::copy(s_u32.begin(), s_u32.end(), s_i64.begin());
    } else {
      readSelection(t, t_space, H5T_NATIVE_INT64, begin, m, s_i64.data(), "/events/t");
    }
    checkRel(s_i64.data(), m, begin, false, 0);
    return s_i64.data();
  }

  // Reads events [begin, begin + m) into out at position `at`; returns the
  // relative time of the last one.
  std::int64_t readBlock(std::uint64_t begin, std::uint64_t m, EventArray& out, std::size_t at,
                         bool have_prev, std::int64_t prev) {
    TimeNs* t_ns = out.t().data() + at;
    const std::int64_t off = t_offset_us;
    std::int64_t last = 0;
    if (t_u32) {
      s_u32.resize(m);
      readSelection(t, t_space, H5T_NATIVE_UINT32, begin, m, s_u32.data(), "/events/t");
      checkRel(s_u32.data(), m, begin, have_prev, prev);
      const std::uint32_t* rel = s_u32.data();
      for (std::uint64_t i = 0; i < m; ++i) t_ns[i] = (off + static_cast<std::int64_t>(rel[i])) * 1000;
      last = rel[m - 1];
    } else {
      readSelection(t, t_space, H5T_NATIVE_INT64, begin, m, t_ns, "/events/t");
      checkRel(t_ns, m, begin, have_prev, prev);
      last = t_ns[m - 1];
      for (std::uint64_t i = 0; i < m; ++i) t_ns[i] = (off + t_ns[i]) * 1000;
    }
    std::uint16_t* xs = out.x().data() + at;
    std::uint16_t* ys = out.y().data() + at;
    std::uint8_t* ps = out.p().data() + at;
    readSelection(x, x_space, H5T_NATIVE_UINT16, begin, m, xs, "/events/x");
    readSelection(y, y_space, H5T_NATIVE_UINT16, begin, m, ys, "/events/y");
    readSelection(p, p_space, H5T_NATIVE_UINT8, begin, m, ps, "/events/p");
    std::uint8_t p_max = 0;
    for (std::uint64_t i = 0; i < m; ++i) p_max = std::max(p_max, ps[i]);
    if (p_max > 1) {
      const std::uint64_t i = static_cast<std::uint64_t>(std::find_if(ps, ps + m, [](std::uint8_t v) {
                                                           return v > 1;
                                                         }) - ps);
      bad("/events/p", "polarity " + std::to_string(ps[i]) + " at index " + str(begin + i) +
                           " is not 0 or 1");
    }
    if (width > 0) {
      checkPixels(xs, m, begin, width, "/events/x", "width");
      checkPixels(ys, m, begin, height, "/events/y", "height");
    }
    return last;
  }

  void checkPixels(const std::uint16_t* v, std::uint64_t m, std::uint64_t begin, int limit,
                   const char* name, const char* what) const {
    std::uint16_t v_max = 0;
    for (std::uint64_t i = 0; i < m; ++i) v_max = std::max(v_max, v[i]);
    if (v_max < limit) return;
    for (std::uint64_t i = 0; i < m; ++i)
      if (v[i] >= limit)
        bad(name, std::to_string(v[i]) + " at index " + str(begin + i) + " is outside the sensor " +
                      what + " " + std::to_string(limit));
  }

  // Reads [begin, begin + count) into out[0..count), validated against event
  // begin - 1 (read when not given).
  void readRange(std::uint64_t begin, std::uint64_t count, EventArray& out, bool have_prev,
                 std::int64_t prev) {
    out.resize(static_cast<std::size_t>(count));
    if (count == 0) return;
    if (!have_prev && begin > 0) {
      prev = readRel(begin - 1);
      have_prev = true;
    }
    for (std::uint64_t done = 0; done < count; done += kBlock) {
      const std::uint64_t m = std::min(kBlock, count - done);
      prev = readBlock(begin + done, m, out, static_cast<std::size_t>(done), have_prev, prev);
      have_prev = true;
    }
  }

  std::uint64_t msAt(std::uint64_t k) {
    std::uint64_t v = 0;
    readSelection(ms, ms_space, H5T_NATIVE_UINT64, k, 1, &v, "/ms_to_idx");
    if (v > n)
      bad("/ms_to_idx", "entry " + str(k) + " = " + str(v) + " exceeds the number of events " +
                            str(n));
    return v;
  }

  [[noreturn]] void msInconsistent(std::uint64_t k, std::uint64_t v) const {
    bad("/ms_to_idx", "entry " + str(k) + " = " + str(v) +
                          " is not the first event at or after " + str(k) + " ms in /events/t");
  }

  // Index of the first event with relative time >= u, found by reading only
  // the events of one millisecond bracketed by /ms_to_idx (entries checked).
  std::uint64_t lowerBound(std::int64_t u) {
    if (n == 0 || u <= r_first) return 0;
    if (u > r_last) return n;
    const std::uint64_t k = static_cast<std::uint64_t>(u / 1000);
    const std::uint64_t j = std::min(k, ms_len - 1);
    const bool has_upper = k + 1 < ms_len;
    const std::uint64_t lo = msAt(j);
    const std::uint64_t hi = has_upper ? msAt(k + 1) : n;
    if (lo > hi) bad("/ms_to_idx", "decreases between entries " + str(j) + " and " + str(k + 1));
    const std::uint64_t a = lo > 0 ? lo - 1 : 0;
    const std::uint64_t b = hi < n ? hi + 1 : n;
    const std::int64_t* rel = loadRel(a, b - a);
    const std::int64_t j_us = static_cast<std::int64_t>(j) * 1000;
    if ((lo > 0 && rel[lo - 1 - a] >= j_us) || (lo < n && rel[lo - a] < j_us)) msInconsistent(j, lo);
    if (has_upper) {
      const std::int64_t k1_us = static_cast<std::int64_t>(k + 1) * 1000;
      if ((hi < n && rel[hi - a] < k1_us) || (hi > 0 && rel[hi - 1 - a] >= k1_us))
        msInconsistent(k + 1, hi);
    }
    return a + static_cast<std::uint64_t>(std::lower_bound(rel + (lo - a), rel + (hi - a), u) - rel);
  }
};

EventH5Reader::EventH5Reader(std::string path, int width, int height)
    : impl_(std::make_unique<Impl>()) {
  h5::QuietErrors quiet;
  impl_->path = std::move(path);
  const LibraryCrashGuard guard("HDF5", impl_->path);  // libhdf5's own crashes on crafted files
  if (width < 0 || height < 0 || width > 65536 || height > 65536 || (width == 0) != (height == 0))
    throw Error::inFile(impl_->path, 0, "invalid sensor size " + std::to_string(width) + "x" +
                                            std::to_string(height));
  impl_->open(width, height);
}

EventH5Reader::~EventH5Reader() {
  h5::QuietErrors quiet;
  impl_.reset();
}

EventH5Reader::EventH5Reader(EventH5Reader&&) noexcept = default;
EventH5Reader& EventH5Reader::operator=(EventH5Reader&& o) noexcept {
  h5::QuietErrors quiet;
  impl_ = std::move(o.impl_);
  return *this;
}

std::uint64_t EventH5Reader::size() const { return impl_->n; }
TimeNs EventH5Reader::tOffsetNs() const { return impl_->t_offset_us * 1000; }
TimeNs EventH5Reader::tFirstNs() const { return (impl_->t_offset_us + impl_->r_first) * 1000; }
TimeNs EventH5Reader::tLastNs() const { return (impl_->t_offset_us + impl_->r_last) * 1000; }
int EventH5Reader::width() const { return impl_->width; }
int EventH5Reader::height() const { return impl_->height; }
const std::string& EventH5Reader::path() const { return impl_->path; }

void EventH5Reader::read(std::uint64_t begin, std::uint64_t count, EventArray& out) {
  h5::QuietErrors quiet;
  const LibraryCrashGuard guard("HDF5", impl_->path);
  if (begin > impl_->n || count > impl_->n - begin)
    throw Error::inFile(impl_->path, 0,
                        "read of events " + str(begin) + " + " + str(count) + " beyond the " +
                            str(impl_->n) + " events of the file");
  impl_->readRange(begin, count, out, false, 0);
}

void EventH5Reader::readWindow(TimeNs t0_ns, TimeNs t1_ns, EventArray& out) {
  h5::QuietErrors quiet;
  const LibraryCrashGuard guard("HDF5", impl_->path);
  Impl& r = *impl_;
  // Event times are (t_offset + rel) * 1000 ns, so t0 <= t  <=>  rel >= ceil(t0 / 1000) - t_offset.
  const std::int64_t u0 = std::max<std::int64_t>(h5::ceilDiv1000(t0_ns) - r.t_offset_us, 0);
  const std::int64_t u1 = h5::ceilDiv1000(t1_ns) - r.t_offset_us;
  if (r.n == 0 || u1 <= u0 || u0 > r.r_last || u1 <= r.r_first) {
    out.clear();
    return;
  }
  const std::uint64_t begin = r.lowerBound(u0);
  const std::uint64_t end = r.lowerBound(u1);
  if (end < begin) r.bad("/ms_to_idx", "inconsistent with /events/t");
  r.readRange(begin, end - begin, out, false, 0);
}

bool EventH5Reader::next(EventArray& out, std::size_t max_events) {
  h5::QuietErrors quiet;
  const LibraryCrashGuard guard("HDF5", impl_->path);
  Impl& r = *impl_;
  if (max_events == 0) throw Error::inFile(r.path, 0, "next(): max_events must be > 0");
  if (r.cursor >= r.n) {
    out.clear();
    return false;
  }
  const std::uint64_t m = std::min<std::uint64_t>(max_events, r.n - r.cursor);
  r.readRange(r.cursor, m, out, r.prev_valid, r.prev_r);
  r.cursor += m;
  r.prev_r = (out.t().back() / 1000) - r.t_offset_us;
  r.prev_valid = true;
  return true;
}

void EventH5Reader::seek(std::uint64_t index) {
  if (index > impl_->n)
    throw Error::inFile(impl_->path, 0,
                        "seek to event " + str(index) + " beyond the " + str(impl_->n) + " events");
  impl_->cursor = index;
  impl_->prev_valid = false;
}

EventArray readEventsH5(const std::string& path, int width, int height) {
  EventH5Reader reader(path, width, height);
  EventArray out;
  reader.read(0, reader.size(), out);
  return out;
}

}  // namespace evio::io
