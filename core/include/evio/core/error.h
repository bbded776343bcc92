#pragma once
/// @file error.h
/// The one exception type of evio. Library code never prints or exits; it
/// throws evio::Error with what failed and where (file:line for inputs).

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace evio {

/// An error with context. `what()` is one line, ready to print:
///   "<file>:<line>: <field>: <message>"  (parts that are unknown are left out).
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}

  /// An error in an input file. `line` is 1-based; 0 means "no line".
  static Error inFile(std::string_view file, std::int64_t line, std::string_view message);

  /// An error in a named field of an input file (a YAML key, an HDF5 dataset,
  /// a column of a text format).
  static Error inField(std::string_view file, std::int64_t line, std::string_view field,
                       std::string_view message);
};

/// Throws Error(message) when `condition` is false.
inline void require(bool condition, const std::string& message) {
  if (!condition) throw Error(message);
}

}  // namespace evio
