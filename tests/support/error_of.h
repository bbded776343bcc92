#pragma once
/// @file error_of.h
/// The message of the evio::Error a callable throws, for tests of error
/// messages (which name the file, line and field).

#include <string>

#include "evio/core/error.h"

namespace evio::test {

/// Runs `f` and returns the evio::Error message it throws ("" if none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace evio::test
