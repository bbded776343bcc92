#pragma once
/// @file events_h5_hdf5.h
/// Private helpers over the HDF5 C API shared by the events_h5*.cpp files:
/// owning handles, switching HDF5's error printing off, and turning HDF5
/// failures into evio::Error. Not installed; never included by a public header.

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <string_view>

#include "evio/core/error.h"

namespace evio::io::h5 {

/// Switches HDF5's automatic error-stack printing off for its lifetime and
/// restores the previous handler afterwards (the setting is per thread).
class QuietErrors {
 public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
  bool saved_ = false;
};

/// An owned HDF5 identifier closed with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      closer_ = o.closer_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; returns false when HDF5 reports a failure.
  bool reset() {
    bool ok = true;
    if (id_ >= 0 && closer_) ok = closer_(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return ok;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

/// The innermost message on HDF5's error stack of this thread ("" if none);
/// clears the stack.
std::string takeHdf5Message();

/// Throws Error "<file>: <field>: <what> (HDF5: <innermost message>)".
[[noreturn]] void fail(const std::string& file, std::string_view field, std::string_view what);

/// Checks an HDF5 identifier / status; on failure calls fail().
hid_t check(hid_t id, const std::string& file, std::string_view field, std::string_view what);
herr_t checkStatus(herr_t status, const std::string& file, std::string_view field,
                   std::string_view what);

inline Handle dataset(hid_t id) { return Handle(id, H5Dclose); }
inline Handle dataspace(hid_t id) { return Handle(id, H5Sclose); }
inline Handle datatype(hid_t id) { return Handle(id, H5Tclose); }
inline Handle plist(hid_t id) { return Handle(id, H5Pclose); }
inline Handle group(hid_t id) { return Handle(id, H5Gclose); }
inline Handle attribute(hid_t id) { return Handle(id, H5Aclose); }
inline Handle file(hid_t id) { return Handle(id, H5Fclose); }

/// A simple 1-D dataspace of n elements.
Handle simpleSpace(std::uint64_t n, const std::string& file, std::string_view field);

/// Selects [begin, begin + count) of a 1-D file dataspace.
void selectRange(hid_t space, std::uint64_t begin, std::uint64_t count, const std::string& file,
                 std::string_view field);

/// floor(t / 1000) and ceil(t / 1000) for any sign (ns -> µs).
constexpr std::int64_t floorDiv1000(std::int64_t t) {
  const std::int64_t q = t / 1000;
  return (t % 1000 < 0) ? q - 1 : q;
}
constexpr std::int64_t ceilDiv1000(std::int64_t t) {
  const std::int64_t q = t / 1000;
  return (t % 1000 > 0) ? q + 1 : q;
}

/// A readable name of an HDF5 datatype ("uint32", "int64", "float64", "string", ...).
std::string typeName(hid_t type);

}  // namespace evio::io::h5
