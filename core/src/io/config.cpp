#include "evio/core/io/config.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"

namespace evio::config {

namespace {

std::vector<std::string> splitPath(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream s(path);
  std::string part;
  while (std::getline(s, part, '.')) parts.push_back(part);
  return parts;
}

}  // namespace

Document loadFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw Error::inFile(path, 0, "not a configuration file (a folder?)");
  std::ifstream in(path);
  if (!in) throw Error::inFile(path, 0, "cannot open configuration file");
  return loadString(io::readFile(path, 64u << 20), path);
}

Document loadString(const std::string& text, const std::string& name) {
  Document doc;
  doc.file = name;
  try {
    doc.root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error::inFile(name, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  if (!doc.root.IsDefined() || doc.root.IsNull()) doc.root = YAML::Node(YAML::NodeType::Map);
  if (!doc.root.IsMap()) throw Error::inFile(name, 1, "expected a YAML map at the top level");
  return doc;
}

void applyOverride(Document& doc, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--set " + assignment + ": expected key.path=value");
  const std::string path = assignment.substr(0, eq);
  const std::string value_text = assignment.substr(eq + 1);
  YAML::Node value;
  try {
    value = YAML::Load(value_text);
  } catch (const YAML::Exception& e) {
    throw Error("--set " + assignment + ": value is not valid YAML: " + e.msg);
  }
  const auto parts = splitPath(path);
  for (const auto& p : parts)
    if (p.empty()) throw Error("--set " + assignment + ": empty key in path");
  // Walk down with fresh node handles (yaml-cpp nodes are references; reassigning
  // a handle would overwrite the parent's child, so each level is indexed anew).
  std::vector<YAML::Node> chain{doc.root};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = chain.back()[parts[i]];
    if (!next.IsDefined() || next.IsNull()) {
      chain.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
      next = chain.back()[parts[i]];
    }
    if (!next.IsMap())
      throw Error("--set " + assignment + ": '" + parts[i] + "' is not a map in " + doc.file);
    chain.push_back(next);
  }
  chain.back()[parts.back()] = value;
  doc.overridden.insert(path);
}

const std::string* overriddenBy(const Document& doc, const std::string& path) {
  for (const auto& o : doc.overridden)
    if (path == o || path.rfind(o + ".", 0) == 0 || path.rfind(o + "[", 0) == 0) return &o;
  return nullptr;
}

std::string where(const Document& doc, const YAML::Node& node, const std::string& path) {
  if (const std::string* o = overriddenBy(doc, path)) return "--set " + *o;
  const auto mark = node.Mark();
  if (mark.line >= 0) return doc.file + ":" + std::to_string(mark.line + 1);
  return doc.file;
}

YAML::Node child(const Document& doc, const std::string& path) {
  YAML::Node node = YAML::Clone(doc.root);
  for (const auto& part : splitPath(path)) {
    if (!node.IsMap()) return YAML::Node(YAML::NodeType::Map);
    YAML::Node next = node[part];
    if (!next.IsDefined()) return YAML::Node(YAML::NodeType::Map);
    node.reset(next);
  }
  return node;
}

void throwAt(const Document& doc, const YAML::Node& node, const std::string& path,
             const std::string& message) {
  throw Error(where(doc, node, path) + ": " + path + ": " + message);
}

void detail::Reader::rejectUnknownKeys() const {
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (!it->first.IsScalar()) throwAt(doc_, it->first, path_, "keys must be plain strings");
    const std::string& key = it->first.Scalar();
    if (!seen_.count(key)) {
      std::string known;
      for (const auto& k : seen_) known += (known.empty() ? "" : ", ") + k;
      throwAt(doc_, it->first, join(key.c_str()), "unknown key (known keys: " + known + ")");
    }
  }
}

template <>
double scalarAs<double>(const Document& doc, const YAML::Node& node, const std::string& path) {
  if (!node.IsScalar()) throwAt(doc, node, path, "expected a number");
  const std::string& s = node.Scalar();
  const std::string lower = [&] {
    std::string l = s;
    for (auto& c : l) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return l;
  }();
  if (lower == ".inf" || lower == "+.inf") return std::numeric_limits<double>::infinity();
  if (lower == "-.inf") return -std::numeric_limits<double>::infinity();
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    throwAt(doc, node, path, "expected a number, got '" + s + "'");
  }
  if (used != s.size()) throwAt(doc, node, path, "expected a number, got '" + s + "'");
  if (std::isnan(v)) throwAt(doc, node, path, "NaN is not allowed");
  return v;
}

template <>
float scalarAs<float>(const Document& doc, const YAML::Node& node, const std::string& path) {
  return static_cast<float>(scalarAs<double>(doc, node, path));
}

template <>
std::int64_t scalarAs<std::int64_t>(const Document& doc, const YAML::Node& node,
                                    const std::string& path) {
  if (!node.IsScalar()) throwAt(doc, node, path, "expected an integer");
  const std::string& s = node.Scalar();
  std::size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(s, &used, 10);
  } catch (const std::exception&) {
    throwAt(doc, node, path, "expected an integer, got '" + s + "'");
  }
  if (used != s.size()) throwAt(doc, node, path, "expected an integer, got '" + s + "'");
  return v;
}

template <>
int scalarAs<int>(const Document& doc, const YAML::Node& node, const std::string& path) {
  const auto v = scalarAs<std::int64_t>(doc, node, path);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throwAt(doc, node, path, "integer out of range");
  return static_cast<int>(v);
}

template <>
std::uint64_t scalarAs<std::uint64_t>(const Document& doc, const YAML::Node& node,
                                      const std::string& path) {
  if (!node.IsScalar()) throwAt(doc, node, path, "expected a non-negative integer");
  const std::string& s = node.Scalar();
  if (!s.empty() && s[0] == '-') throwAt(doc, node, path, "expected a non-negative integer");
  std::size_t used = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(s, &used, 10);
  } catch (const std::exception&) {
    throwAt(doc, node, path, "expected a non-negative integer, got '" + s + "'");
  }
  if (used != s.size()) throwAt(doc, node, path, "expected a non-negative integer, got '" + s + "'");
  return v;
}

template <>
bool scalarAs<bool>(const Document& doc, const YAML::Node& node, const std::string& path) {
  if (!node.IsScalar()) throwAt(doc, node, path, "expected true or false");
  const std::string& s = node.Scalar();
  if (s == "true" || s == "True" || s == "TRUE" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "False" || s == "FALSE" || s == "no" || s == "off") return false;
  throwAt(doc, node, path, "expected true or false, got '" + s + "'");
}

template <>
std::string scalarAs<std::string>(const Document& doc, const YAML::Node& node,
                                  const std::string& path) {
  if (!node.IsScalar()) throwAt(doc, node, path, "expected a string");
  return node.Scalar();
}

std::string yamlNumber(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  // Whole numbers as integers ("10", not "1e+01", which YAML 1.1 readers
  // such as PyYAML take for a string).
  if (v == std::floor(v) && std::fabs(v) < 1e15) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.0f", v);
    return std::string(buf) == "-0" ? "0" : buf;
  }
  // Else the shortest representation that round-trips, with a '.' in the
  // mantissa whenever there is an exponent ("1.0e-05", not "1e-05").
  std::string text;
  for (int p = 1; p <= 17; ++p) {
    std::ostringstream t;
    t.precision(p);
    t << v;
    text = t.str();
    if (std::strtod(text.c_str(), nullptr) == v) break;  // strtod: no exception for subnormals
  }
  const std::size_t e = text.find('e');
  if (e != std::string::npos && text.find('.') == std::string::npos) text.insert(e, ".0");
  return text;
}

void emitDouble(YAML::Emitter& out, double v) { out << yamlNumber(v); }

}  // namespace evio::config
