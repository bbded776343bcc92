#pragma once
/// @file config.h
/// YAML configuration: fills Options structs through their `fields()` list,
/// rejects unknown keys and wrong types with file:line, applies command-line
/// overrides `--set a.b.c=value`, and writes the resolved configuration back.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/options.h"

namespace evio::config {

/// A YAML document with where it came from (for error messages) and the set
/// of key paths that were set on the command line.
struct Document {
  YAML::Node root;
  std::string file;                    ///< file name for messages ("<string>" if none)
  std::set<std::string> overridden;    ///< dotted paths set by --set
};

/// Parses a YAML file; throws Error naming the file and line on a syntax error
/// or when the file cannot be opened.
Document loadFile(const std::string& path);

/// Parses YAML text; `name` is used in messages.
Document loadString(const std::string& text, const std::string& name = "<string>");

/// Applies one override "a.b.c=value" (value parsed as YAML). Creates
/// intermediate maps. Throws Error on a malformed override.
void applyOverride(Document& doc, const std::string& assignment);

/// The set path that dotted `path` was set by on the command line (itself
/// or a map or list above it), or nullptr when the file gave it.
const std::string* overriddenBy(const Document& doc, const std::string& path);

/// Where a node is, for messages: "file:line" or "--set a.b=…".
std::string where(const Document& doc, const YAML::Node& node, const std::string& path);

/// Returns the sub-document at dotted `path` (an empty map when absent).
YAML::Node child(const Document& doc, const std::string& path);

// Building blocks for modules that read or write YAML beyond Options structs.

/// Throws Error "file:line: path: message" (or "--set path=…: path: message"
/// for a value set on the command line) for `node` at dotted `path`.
[[noreturn]] void throwAt(const Document& doc, const YAML::Node& node, const std::string& path,
                          const std::string& message);

/// The scalar `node` as T (double, float, int, int64, uint64, bool, string);
/// throws through throwAt when it is not a scalar of that type. Doubles accept
/// .inf/-.inf and reject NaN.
template <class T>
T scalarAs(const Document& doc, const YAML::Node& node, const std::string& path);
template <> double scalarAs<double>(const Document&, const YAML::Node&, const std::string&);
template <> float scalarAs<float>(const Document&, const YAML::Node&, const std::string&);
template <> int scalarAs<int>(const Document&, const YAML::Node&, const std::string&);
template <> std::int64_t scalarAs<std::int64_t>(const Document&, const YAML::Node&, const std::string&);
template <> std::uint64_t scalarAs<std::uint64_t>(const Document&, const YAML::Node&, const std::string&);
template <> bool scalarAs<bool>(const Document&, const YAML::Node&, const std::string&);
template <> std::string scalarAs<std::string>(const Document&, const YAML::Node&, const std::string&);

/// Reads a value of type T from a node at dotted `path` (for messages):
/// scalars, std::vector, fixed-size Eigen matrices (row-major list) and
/// Options structs (a map through fields(), unknown keys rejected, no
/// validate()). Throws through throwAt.
template <class T>
void readValue(const Document& doc, const YAML::Node& node, const std::string& path, T& out);

/// A double as YAML text that reads back to the same value and that every
/// YAML reader (1.1 and 1.2: yaml-cpp, PyYAML, OpenCV) takes for a number:
/// whole numbers below 1e15 as integers ("10"), others the shortest
/// round-trip text with a '.' in any mantissa ("0.25", "1.0e-05"), and
/// .inf, -.inf, .nan.
std::string yamlNumber(double v);

/// Writes yamlNumber(v).
void emitDouble(YAML::Emitter& out, double v);

/// Writes fields() of an Options struct (or any value readValue reads) into
/// an emitter: `Writer(out).write(options)` emits a map; doubles go through
/// emitDouble, vectors and Eigen matrices as flow lists.
class Writer {
 public:
  explicit Writer(YAML::Emitter& out) : out_(out) {}
  template <class T>
  void operator()(const char* key, const T& field, const char* /*doc*/ = "") {
    out_ << YAML::Key << key << YAML::Value;
    write(field);
  }
  template <class T>
  void write(const T& field);

 private:
  YAML::Emitter& out_;
};

namespace detail {

template <class T>
struct IsStdVector : std::false_type {};
template <class T, class A>
struct IsStdVector<std::vector<T, A>> : std::true_type {};

class Reader {
 public:
  Reader(const Document& doc, YAML::Node node, std::string path)
      : doc_(doc), node_(std::move(node)), path_(std::move(path)) {}

  template <class T>
  void operator()(const char* key, T& field, const char* /*doc*/ = "") {
    seen_.insert(key);
    const YAML::Node value = node_[key];
    if (!value.IsDefined() || value.IsNull()) return;  // keep the default
    readValue(doc_, value, join(key), field);
  }

  /// Throws for keys of the map that no field claimed.
  void rejectUnknownKeys() const;

 private:
  std::string join(const char* key) const { return path_.empty() ? key : path_ + "." + key; }
  const Document& doc_;
  YAML::Node node_;
  std::string path_;
  std::set<std::string> seen_;
};

}  // namespace detail

template <class T>
void readValue(const Document& doc, const YAML::Node& node, const std::string& path, T& out) {
  if constexpr (IsVisitable<T>::value) {
    if (!node.IsMap()) throwAt(doc, node, path, "expected a map of options");
    detail::Reader reader(doc, node, path);
    out.fields(reader);
    reader.rejectUnknownKeys();
  } else if constexpr (detail::IsStdVector<T>::value) {
    if (!node.IsSequence()) throwAt(doc, node, path, "expected a list");
    out.clear();
    for (std::size_t i = 0; i < node.size(); ++i) {
      typename T::value_type item{};
      readValue(doc, node[i], path + "[" + std::to_string(i) + "]", item);
      out.push_back(std::move(item));
    }
  } else if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
    static_assert(T::SizeAtCompileTime > 0, "only fixed-size Eigen types in Options");
    if (!node.IsSequence() || node.size() != static_cast<std::size_t>(T::SizeAtCompileTime))
      throwAt(doc, node, path,
              "expected a list of " + std::to_string(T::SizeAtCompileTime) + " numbers (row-major)");
    for (int i = 0; i < T::SizeAtCompileTime; ++i) {
      // Row-major listing: element i is (i / cols, i % cols).
      out(i / T::ColsAtCompileTime, i % T::ColsAtCompileTime) =
          scalarAs<double>(doc, node[static_cast<std::size_t>(i)], path + "[" + std::to_string(i) + "]");
    }
  } else {
    out = scalarAs<T>(doc, node, path);
  }
}

template <class T>
void Writer::write(const T& field) {
  if constexpr (IsVisitable<T>::value) {
    out_ << YAML::BeginMap;
    const_cast<T&>(field).fields(*this);
    out_ << YAML::EndMap;
  } else if constexpr (detail::IsStdVector<T>::value) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (const auto& item : field) write(item);
    out_ << YAML::EndSeq;
  } else if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (int i = 0; i < T::SizeAtCompileTime; ++i)
      emitDouble(out_, field(i / T::ColsAtCompileTime, i % T::ColsAtCompileTime));
    out_ << YAML::EndSeq;
  } else if constexpr (std::is_floating_point_v<T>) {
    emitDouble(out_, static_cast<double>(field));
  } else {
    out_ << field;
  }
}

/// Fills `options` from the map at dotted `path` of `doc` (the root when
/// empty), then calls validate(); validation errors name the file.
template <class Options>
void fill(const Document& doc, const std::string& path, Options& options) {
  const YAML::Node node = path.empty() ? doc.root : child(doc, path);
  try {
    if (node.IsDefined() && !node.IsNull()) readValue(doc, node, path, options);
  } catch (const YAML::Exception& e) {  // anything yaml-cpp itself rejects
    throw Error::inFile(doc.file, e.mark.line + 1, "invalid YAML: " + e.msg);
  }
  try {
    options.validate();
  } catch (const Error& e) {
    throw Error(doc.file + ": " + (path.empty() ? "" : path + ".") + e.what());
  }
}

/// Loads a file, applies overrides and fills `Options` from its root.
template <class Options>
Options load(const std::string& file, const std::vector<std::string>& overrides = {}) {
  Document doc = loadFile(file);
  for (const auto& o : overrides) applyOverride(doc, o);
  Options options;
  fill(doc, "", options);
  return options;
}

/// The options as a YAML map (every field, defaults included).
template <class Options>
std::string toYaml(const Options& options) {
  YAML::Emitter out;
  Writer writer(out);
  writer.write(options);
  return std::string(out.c_str()) + "\n";
}

/// Field-by-field equality derived from fields(): two options are equal when
/// they print the same (doubles print with round-trip precision).
template <class Options>
bool equal(const Options& a, const Options& b) {
  return toYaml(a) == toYaml(b);
}

}  // namespace evio::config
