#pragma once
/// @file method.h
/// The estimator methods, one registry: what each reads and which frontend it
/// runs (docs/architecture.md#the-estimator-stages). A new method is one entry
/// here and, when it brings a tracker, one FeatureTracker in the frontend.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace evio::estimator {

enum class Method {
  kEkltVio,  ///< EKLT on events and frames (or frames reconstructed from events)
  kKltVio,   ///< KLT on the frames, one backend update per frame
  kHasteVio, ///< HASTE on events (seeded on frames or frames reconstructed from events)
  kTracks,   ///< no frontend: feature tracks read from a file (the backend in isolation)
};

struct MethodInfo {
  Method method;
  const char* name;          ///< as on the command line and in config files
  const char* tracker;       ///< frontend.tracker it runs ("" for none)
  const char* sync_trigger;  ///< its synchroniser trigger (synchronizer.h)
  bool reads_events;         ///< events feed the tracker
  bool tracks_frame_camera;  ///< tracks in the frame camera's pixels (else the event camera's)
};

/// The entry of `method`.
const MethodInfo& methodInfo(Method method);
/// The method named `name`; nullopt for an unknown name.
std::optional<Method> parseMethod(std::string_view name);
/// "eklt-vio, klt-vio, haste-vio, tracks" (for messages and the CLI).
std::string methodNames();
/// Every method's entry, in that order.
std::vector<MethodInfo> allMethods();

}  // namespace evio::estimator
