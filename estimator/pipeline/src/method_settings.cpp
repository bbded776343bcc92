#include "evio/estimator/pipeline/method_settings.h"

#include <string>
#include <vector>

#include "evio/estimator/pipeline/method.h"

namespace evio::estimator {

namespace {

// True when `path` or a map above it was set on the command line.
bool setOnCommandLine(const config::Document& doc, const std::string& path) {
  for (const std::string& o : doc.overridden)
    if (path == o || path.rfind(o + ".", 0) == 0) return true;
  return false;
}

// Copies every key of `section` into `target` at `prefix`, recursing into
// maps present in both; nodes are shared, so messages about them still
// name the section's file and line.
void mergeSection(const config::Document& doc, YAML::Node target, const YAML::Node& section,
                  const std::string& prefix) {
  for (const auto& kv : section) {
    const std::string key = kv.first.as<std::string>();
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    if (setOnCommandLine(doc, path)) continue;
    YAML::Node existing = target[key];
    if (kv.second.IsMap() && existing.IsDefined() && existing.IsMap()) {
      mergeSection(doc, existing, kv.second, path);
    } else {
      target[key] = kv.second;
    }
  }
}

}  // namespace

void applyMethodSettings(config::Document& doc, std::string_view method) {
  std::vector<std::string> names;
  for (const MethodInfo& m : allMethods()) names.emplace_back(m.name);
  for (const std::string& name : names) {
    const YAML::Node section = doc.root[name];
    if (!section.IsDefined() || section.IsNull()) continue;
    if (!section.IsMap()) config::throwAt(doc, section, name, "expected a map of settings for " + name + " only");
  }
  const YAML::Node own = doc.root[std::string(method)];
  if (own.IsDefined() && own.IsMap()) mergeSection(doc, doc.root, own, "");
  for (const std::string& name : names) doc.root.remove(name);
}

}  // namespace evio::estimator
