#include "evio/trajectories/trajectory_factory.h"

#include <filesystem>

#include "evio/core/error.h"
#include "evio/trajectories/circle.h"
#include "evio/trajectories/flight.h"
#include "evio/trajectories/from_file.h"
#include "evio/trajectories/hand_held.h"
#include "evio/trajectories/hover.h"
#include "evio/trajectories/lava_tube_entry.h"
#include "evio/trajectories/rotation_only.h"

namespace evio {

const std::vector<std::string>& trajectoryTypes() {
  static const std::vector<std::string> types = {"hover",       "rotation_only", "circle",
                                                 "six_dof",     "translation",   "flight",
                                                 "lava_tube_entry", "from_file"};
  return types;
}

namespace {

template <class Options, class Trajectory>
std::unique_ptr<ContinuousTrajectory> build(const config::Document& doc, const std::string& path) {
  Options options;
  config::fill(doc, path, options);
  return std::make_unique<Trajectory>(options);
}

}  // namespace

std::unique_ptr<ContinuousTrajectory> makeTrajectory(const config::Document& doc,
                                                     const std::string& path) {
  const YAML::Node node = path.empty() ? doc.root : config::child(doc, path);
  const std::string type_path = path.empty() ? "type" : path + ".type";
  std::string known;
  for (const auto& t : trajectoryTypes()) known += (known.empty() ? "" : ", ") + t;
  if (!node.IsMap() || !node["type"].IsDefined() || node["type"].IsNull())
    config::throwAt(doc, node, type_path, "missing (one of: " + known + ")");
  const std::string type = config::scalarAs<std::string>(doc, node["type"], type_path);

  if (type == "hover") return build<HoverOptions, HoverTrajectory>(doc, path);
  if (type == "rotation_only") return build<RotationOnlyOptions, RotationOnlyTrajectory>(doc, path);
  if (type == "circle") return build<CircleOptions, CircleTrajectory>(doc, path);
  if (type == "six_dof") return build<HandHeldOptions, HandHeldTrajectory>(doc, path);
  if (type == "translation") return build<TranslationOptions, HandHeldTrajectory>(doc, path);
  if (type == "flight") return build<FlightOptions, FlightTrajectory>(doc, path);
  if (type == "lava_tube_entry") return build<LavaTubeEntryOptions, LavaTubeEntryTrajectory>(doc, path);
  if (type == "from_file") {
    FromFileOptions options;
    config::fill(doc, path, options);
    const std::string folder =
        doc.file.empty() || doc.file[0] == '<' ? "" : std::filesystem::path(doc.file).parent_path().string();
    try {
      return makeFromFileTrajectory(options, folder);
    } catch (const Error& e) {
      throw Error(config::where(doc, node, path) + ": " + e.what());
    }
  }
  config::throwAt(doc, node["type"], type_path,
                          "unknown trajectory type '" + type + "' (one of: " + known + ")");
}

std::unique_ptr<ContinuousTrajectory> makeTrajectory(const std::string& yaml_file,
                                                     const std::vector<std::string>& overrides) {
  config::Document doc = config::loadFile(yaml_file);
  for (const auto& o : overrides) config::applyOverride(doc, o);
  return makeTrajectory(doc, "");
}

}  // namespace evio
