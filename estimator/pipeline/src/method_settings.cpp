#include "evio/estimator/pipeline/method_settings.h"

#include <string>
#include <vector>

#include "evio/estimator/pipeline/method.h"

namespace evio::estimator {

namespace {

// Copies every key of `section` into `target` at `prefix`, recursing into
// maps present in both; nodes are shared, so messages about them still
// name the section's file and line.
void mergeSection(const config::Document& doc, YAML::Node target, const YAML::Node& section,
                  const std::string& prefix) {
  for (const auto& kv : section) {
    const std::string key = kv.first.as<std::string>();
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    if (config::overriddenBy(doc, path) != nullptr) continue;  // --set wins
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
  const std::vector<MethodInfo> methods = allMethods();
  for (const MethodInfo& m : methods) {
    const YAML::Node section = doc.root[m.name];
    if (section.IsDefined() && !section.IsNull() && !section.IsMap())
      config::throwAt(doc, section, m.name, "expected a map of settings for " + std::string(m.name) + " only");
  }
  const YAML::Node own = doc.root[std::string(method)];
  if (own.IsDefined() && own.IsMap()) mergeSection(doc, doc.root, own, "");
  for (const MethodInfo& m : methods) doc.root.remove(m.name);
}

}  // namespace evio::estimator
