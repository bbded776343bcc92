#include "evio/experiments/json_value.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "evio/core/error.h"
#include "evio/core/io/text_scanner.h"

namespace evio::experiments {

JsonValue JsonValue::boolean(bool b) {
  JsonValue v;
  v.kind_ = Kind::kBool;
  v.text_ = b ? "true" : "false";
  return v;
}

JsonValue JsonValue::number(double x) {
  if (!std::isfinite(x)) return {};
  JsonValue v;
  v.kind_ = Kind::kNumber;
  io::appendDouble(v.text_, x == 0.0 ? 0.0 : x);  // no "-0"
  return v;
}

JsonValue JsonValue::integer(std::int64_t x) {
  JsonValue v;
  v.kind_ = Kind::kNumber;
  io::appendInt(v.text_, x);
  return v;
}

JsonValue JsonValue::numberText(std::string text) {
  JsonValue v;
  v.kind_ = Kind::kNumber;
  v.text_ = std::move(text);
  return v;
}

JsonValue JsonValue::string(std::string s) {
  JsonValue v;
  v.kind_ = Kind::kString;
  v.text_ = std::move(s);
  return v;
}

JsonValue JsonValue::array() {
  JsonValue v;
  v.kind_ = Kind::kArray;
  return v;
}

JsonValue JsonValue::object() {
  JsonValue v;
  v.kind_ = Kind::kObject;
  return v;
}

double JsonValue::asDouble() const {
  if (kind_ != Kind::kNumber) return std::numeric_limits<double>::quiet_NaN();
  double x = 0.0;
  return io::parseFiniteDouble(text_, &x) ? x : std::numeric_limits<double>::quiet_NaN();
}

JsonValue& JsonValue::set(const std::string& key, JsonValue value) {
  require(kind_ == Kind::kObject, "JsonValue::set on a non-object");
  for (auto& [k, v] : members_)
    if (k == key) return v = std::move(value);
  members_.emplace_back(key, std::move(value));
  return members_.back().second;
}

JsonValue& JsonValue::push(JsonValue value) {
  require(kind_ == Kind::kArray, "JsonValue::push on a non-array");
  items_.push_back(std::move(value));
  return items_.back();
}

const JsonValue* JsonValue::find(const std::string& key) const {
  for (const auto& [k, v] : members_)
    if (k == key) return &v;
  return nullptr;
}

const JsonValue* JsonValue::at(const std::string& path) const {
  const JsonValue* v = this;
  std::size_t begin = 0;
  while (v && begin <= path.size()) {
    const std::size_t dot = path.find('.', begin);
    v = v->find(path.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin));
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  return v;
}

std::string jsonQuote(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

void JsonValue::dumpTo(std::string& out, int indent) const {
  const std::string pad(static_cast<std::size_t>(indent + 2), ' ');
  switch (kind_) {
    case Kind::kNull: out += "null"; return;
    case Kind::kBool:
    case Kind::kNumber: out += text_; return;
    case Kind::kString: out += jsonQuote(text_); return;
    case Kind::kArray: {
      bool scalars = true;
      for (const auto& i : items_) scalars = scalars && i.kind_ != Kind::kArray && i.kind_ != Kind::kObject;
      out += "[";
      for (std::size_t i = 0; i < items_.size(); ++i) {
        out += i == 0 ? "" : ",";
        if (scalars) {
          out += i == 0 ? "" : " ";
        } else {
          out += "\n" + pad;
        }
        items_[i].dumpTo(out, indent + 2);
      }
      if (!scalars && !items_.empty()) out += "\n" + std::string(static_cast<std::size_t>(indent), ' ');
      out += "]";
      return;
    }
    case Kind::kObject: {
      out += "{";
      for (std::size_t i = 0; i < members_.size(); ++i) {
        out += (i == 0 ? "\n" : ",\n") + pad + jsonQuote(members_[i].first) + ": ";
        members_[i].second.dumpTo(out, indent + 2);
      }
      if (!members_.empty()) out += "\n" + std::string(static_cast<std::size_t>(indent), ' ');
      out += "}";
      return;
    }
  }
}

std::string JsonValue::dump() const {
  std::string out;
  dumpTo(out, 0);
  return out + "\n";
}

void JsonValue::flatten(std::vector<std::pair<std::string, std::string>>& out, const std::string& prefix) const {
  if (kind_ == Kind::kArray) return;
  if (kind_ == Kind::kObject) {
    for (const auto& [k, v] : members_) v.flatten(out, prefix.empty() ? k : prefix + "." + k);
    return;
  }
  out.emplace_back(prefix, text_);
}

namespace {

JsonValue fromYaml(const YAML::Node& node, const std::string& name) {
  switch (node.Type()) {
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined: return JsonValue::null();
    case YAML::NodeType::Sequence: {
      JsonValue a = JsonValue::array();
      for (const auto& item : node) a.push(fromYaml(item, name));
      return a;
    }
    case YAML::NodeType::Map: {
      JsonValue o = JsonValue::object();
      for (auto it = node.begin(); it != node.end(); ++it) o.set(it->first.Scalar(), fromYaml(it->second, name));
      return o;
    }
    case YAML::NodeType::Scalar: break;
  }
  const std::string& s = node.Scalar();
  if (node.Tag() == "!") return JsonValue::string(s);  // quoted
  if (s == "true" || s == "false") return JsonValue::boolean(s == "true");
  if (s == "null" || s == "~") return JsonValue::null();
  double x = 0.0;
  if (io::parseFiniteDouble(s, &x)) return JsonValue::numberText(s);
  throw Error::inFile(name, node.Mark().line + 1, "not a JSON value: '" + s + "'");
}

}  // namespace

JsonValue parseJson(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error::inFile(name, e.mark.line + 1, "invalid JSON: " + e.msg);
  }
  return fromYaml(root, name);
}

}  // namespace evio::experiments
