#include "evio/estimator/pipeline/method.h"

#include <array>

namespace evio::estimator {

namespace {
constexpr std::array<MethodInfo, 4> kMethods{{
    {Method::kEkltVio, "eklt-vio", "eklt", "events", true, false},
    {Method::kKltVio, "klt-vio", "klt", "track_time", false, true},
    {Method::kHasteVio, "haste-vio", "haste", "events", true, false},
    {Method::kTracks, "tracks", "", "events", false, false},
}};
}  // namespace

const MethodInfo& methodInfo(Method method) {
  for (const MethodInfo& m : kMethods)
    if (m.method == method) return m;
  return kMethods.front();  // unreachable: every enumerator has an entry
}

std::optional<Method> parseMethod(std::string_view name) {
  for (const MethodInfo& m : kMethods)
    if (name == m.name) return m.method;
  return std::nullopt;
}

std::string methodNames() {
  std::string out;
  for (const MethodInfo& m : kMethods) out += (out.empty() ? "" : ", ") + std::string(m.name);
  return out;
}

std::vector<MethodInfo> allMethods() { return {kMethods.begin(), kMethods.end()}; }

}  // namespace evio::estimator
