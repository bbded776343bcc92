#pragma once
/// @file options.h
/// The Options pattern (docs/architecture.md#configuration). Every component has a
/// `struct Options` with in-class defaults, units in field names, a `///`
/// comment per field, a `validate()` that throws evio::Error naming the
/// field, and a `fields(v)` that lists its fields once:
///
///   struct Options {
///     double exposure_s = 0.01;  ///< exposure time in seconds
///     template <class V> void fields(V& v) {
///       v("exposure_s", exposure_s, "exposure time in seconds");
///     }
///     void validate() const { requirePositive("exposure_s", exposure_s); }
///   };
///
/// From that single list the YAML loader fills the struct (rejecting unknown
/// keys), the writer prints it, and equality is derived (core/io/config.h).
/// Nested Options are visited as nested maps.

#include <cmath>
#include <string>
#include <string_view>
#include <type_traits>

#include "evio/core/error.h"

namespace evio {

/// True for types with a `fields(V&)` member: they are nested option maps.
template <class T, class = void>
struct IsVisitable : std::false_type {};
template <class T>
struct IsVisitable<T, std::void_t<decltype(std::declval<T&>().fields(std::declval<int&>()))>>
    : std::true_type {};

/// Throws Error "<field>: must be > 0 (got v)" unless v > 0 and finite.
void requirePositive(std::string_view field, double value);
/// Throws unless v >= 0 and finite.
void requireNonNegative(std::string_view field, double value);
/// Throws unless lo <= v <= hi.
void requireInRange(std::string_view field, double value, double lo, double hi);
/// Throws Error "<field>: <message>" unless condition holds.
void requireField(bool condition, std::string_view field, std::string_view message);

/// Runs a nested options struct's validate() and prefixes its error with
/// the section's name, so the message names the key as it is set
/// ("haste.margin: must be in …").
template <class Options>
void validateSection(std::string_view section, const Options& options) {
  try {
    options.validate();
  } catch (const Error& e) {
    throw Error(std::string(section) + "." + e.what());
  }
}

}  // namespace evio
