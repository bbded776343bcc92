#pragma once
/// @file json_value.h
/// A small JSON document tree for metrics files: objects keep their keys in
/// insertion order (so files are stable and diff well), numbers keep their
/// text (shortest round-trip form when built from a double; non-finite
/// doubles become null). Serialises to indented JSON, flattens to dotted
/// key/value pairs for CSV, and parses JSON text back (through yaml-cpp,
/// JSON being a subset of YAML 1.2).

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace evio::experiments {

class JsonValue {
 public:
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject };

  JsonValue() = default;  ///< null
  static JsonValue null() { return {}; }
  static JsonValue boolean(bool b);
  static JsonValue number(double v);          ///< NaN/inf → null
  static JsonValue integer(std::int64_t v);
  static JsonValue numberText(std::string text);  ///< verbatim number text
  static JsonValue string(std::string s);
  static JsonValue array();
  static JsonValue object();

  Kind kind() const { return kind_; }
  bool isNull() const { return kind_ == Kind::kNull; }
  /// Text of a scalar: "true"/"false", the number text, the string; "" for null.
  const std::string& text() const { return text_; }
  /// Number value (NaN for non-numbers).
  double asDouble() const;

  /// Object: sets `key` (replacing an existing key in place). Returns the value.
  JsonValue& set(const std::string& key, JsonValue value);
  /// Array: appends. Returns the value.
  JsonValue& push(JsonValue value);

  /// Object member or nullptr.
  const JsonValue* find(const std::string& key) const;
  /// Member by dotted path ("ate.position_m.rmse") or nullptr.
  const JsonValue* at(const std::string& dotted_path) const;
  const std::vector<std::pair<std::string, JsonValue>>& members() const { return members_; }
  const std::vector<JsonValue>& items() const { return items_; }

  /// Indented JSON text ending with a newline (2 spaces per level; arrays of
  /// scalars on one line).
  std::string dump() const;

  /// Scalar leaves as ("a.b.c", text) in document order; arrays are skipped.
  void flatten(std::vector<std::pair<std::string, std::string>>& out, const std::string& prefix = "") const;

 private:
  void dumpTo(std::string& out, int indent) const;
  Kind kind_ = Kind::kNull;
  std::string text_;
  std::vector<std::pair<std::string, JsonValue>> members_;
  std::vector<JsonValue> items_;
};

/// Parses JSON text; `name` (a file name) is used in evio::Error messages.
JsonValue parseJson(const std::string& text, const std::string& name);

/// The JSON string literal of `s` (quoted, escaped).
std::string jsonQuote(const std::string& s);

}  // namespace evio::experiments
