// Loading a scenario: presets, merges, overrides and the resolved YAML.
#include "evio/simulator/scenario.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/version.h"
#include "evio/trajectories/trajectory_factory.h"

namespace evio::simulator {

namespace fs = std::filesystem;

namespace {

/// The sections that may name a preset: a path, {preset: path, ...} or inline.
constexpr const char* kScene = "scene";
constexpr const char* kTrajectory = "trajectory";

/// `relative` tried against base_dir, then search_root; absolute paths as they are.
std::string resolvePath(const std::string& relative, const std::string& base_dir, const std::string& search_root,
                        const std::string& where) {
  const fs::path p(relative);
  if (p.is_absolute()) {
    if (fs::is_regular_file(p)) return p.string();
  } else {
    const fs::path first = base_dir.empty() ? p : fs::path(base_dir) / p;
    if (fs::is_regular_file(first)) return first.lexically_normal().string();
    if (!search_root.empty() && fs::is_regular_file(fs::path(search_root) / p))
      return (fs::path(search_root) / p).lexically_normal().string();
  }
  throw Error(where + ": file not found: '" + relative + "' (tried relative to '" +
              (base_dir.empty() ? "." : base_dir) + "'" + (search_root.empty() ? "" : " and '" + search_root + "'") +
              ")");
}

/// Copies `overlay`'s keys over `base` (a clone); maps merge key by key.
void mergeInto(YAML::Node base, const YAML::Node& overlay) {
  for (auto it = overlay.begin(); it != overlay.end(); ++it) {
    const std::string key = it->first.Scalar();
    YAML::Node b = base[key];
    if (b.IsDefined() && b.IsMap() && it->second.IsMap())
      mergeInto(b, it->second);
    else
      base[key] = it->second;  // shared, keeps its line numbers for messages
  }
}

/// The overridden paths below `prefix.`, relative to it.
std::set<std::string> overriddenBelow(const config::Document& doc, const std::string& prefix) {
  std::set<std::string> out;
  for (const auto& o : doc.overridden)
    if (o.rfind(prefix + ".", 0) == 0) out.insert(o.substr(prefix.size() + 1));
  return out;
}

/// A section that may name a preset, as one document: the preset file (if
/// any) with the keys beside `preset` merged over it. `*dir` receives the
/// folder its relative paths resolve against; `*preset_doc` the preset alone.
config::Document sectionDocument(const config::Document& doc, const YAML::Node& node, const std::string& section,
                                 const std::string& base_dir, const std::string& search_root, std::string* dir,
                                 std::optional<config::Document>* preset_doc) {
  const std::string where = config::where(doc, node, section);
  std::string preset_path;
  YAML::Node overlay(YAML::NodeType::Map);
  if (node.IsScalar()) {
    preset_path = node.Scalar();
  } else if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (!it->first.IsScalar()) config::throwAt(doc, it->first, section, "keys must be plain strings");
      if (it->first.Scalar() == "preset") {
        if (!it->second.IsScalar())
          config::throwAt(doc, it->second, section + ".preset", "expected a file path");
        preset_path = it->second.Scalar();
      } else {
        overlay[it->first.Scalar()] = it->second;
      }
    }
  } else {
    config::throwAt(doc, node, section, "expected a file path or a map");
  }
  config::Document out;
  out.overridden = overriddenBelow(doc, section);
  if (preset_path.empty()) {
    out.root = overlay;  // the scenario's own nodes: messages keep their lines
    out.file = doc.file;
    *dir = base_dir;
    return out;
  }
  const std::string path = resolvePath(preset_path, base_dir, search_root, where + ": " + section);
  *preset_doc = config::loadFile(path);
  if (!(*preset_doc)->root.IsMap()) throw Error(path + ": expected a map");
  out.root = YAML::Clone((*preset_doc)->root);
  mergeInto(out.root, overlay);
  out.file = overlay.size() > 0 ? doc.file + " (over " + path + ")" : path;
  *dir = fs::path(path).parent_path().string();
  return out;
}

/// Scalars named in overrides below a preset section become {preset: path}
/// maps first, so `--set trajectory.center_m=...` adds a key beside it.
void presetScalarsToMaps(config::Document& doc, const std::vector<std::string>& overrides) {
  if (!doc.root.IsMap()) return;
  for (const std::string section : {"scene", "trajectory"}) {
    bool touched = false;
    for (const auto& o : overrides) touched = touched || o.rfind(section + ".", 0) == 0;
    YAML::Node n = doc.root[section];
    if (touched && n.IsDefined() && n.IsScalar()) {
      YAML::Node m(YAML::NodeType::Map);
      m["preset"] = n.Scalar();
      doc.root[section] = m;
    }
  }
}

Scenario loadScenarioDocument(config::Document doc, const std::string& base_dir, const std::string& search_root) {
  if (!doc.root.IsMap()) throw Error(doc.file + ": a scenario must be a map");
  Scenario s;
  s.file = doc.file;
  ScenarioOptions& o = s.options;

  // 1. The event camera: its preset first (errors name the preset file), then the scenario's keys.
  const YAML::Node rig_node = doc.root["rig"];
  const YAML::Node cam_node = rig_node.IsMap() ? rig_node["event_camera"] : YAML::Node();
  if (cam_node.IsDefined() && !cam_node.IsNull()) {
    if (!cam_node.IsMap()) config::throwAt(doc, cam_node, "rig.event_camera", "expected a map");
    const YAML::Node preset = cam_node["preset"];
    if (preset.IsDefined() && !preset.IsNull() && !(preset.IsScalar() && preset.Scalar().empty())) {
      if (!preset.IsScalar()) config::throwAt(doc, preset, "rig.event_camera.preset", "expected a file path");
      const std::string path = resolvePath(preset.Scalar(), base_dir, search_root,
                                           config::where(doc, preset, "rig.event_camera.preset"));
      config::fill(config::loadFile(path), "", o.rig.event_camera.sensor);
    }
  }
  config::Document camera_doc{cam_node.IsDefined() ? cam_node : YAML::Node(YAML::NodeType::Map), doc.file,
                              overriddenBelow(doc, "rig.event_camera")};
  config::fill(camera_doc, "", o.rig.event_camera);

  // 1b. The frame camera's sensor preset, under the scenario's keys.
  const YAML::Node frame_node = rig_node.IsMap() ? rig_node["frame_camera"] : YAML::Node();
  if (frame_node.IsDefined() && frame_node.IsMap()) {
    const YAML::Node preset = frame_node["preset"];
    if (preset.IsDefined() && !preset.IsNull() && !(preset.IsScalar() && preset.Scalar().empty())) {
      if (!preset.IsScalar()) config::throwAt(doc, preset, "rig.frame_camera.preset", "expected a file path");
      const std::string path = resolvePath(preset.Scalar(), base_dir, search_root,
                                           config::where(doc, preset, "rig.frame_camera.preset"));
      config::fill(config::loadFile(path), "", o.rig.frame_camera.sensor);
    }
  }

  // 2. Every other field: the sections read on their own are taken out of
  // the (local) document, which keeps its nodes' line numbers (a clone would not).
  const YAML::Node scene_node = doc.root[kScene];
  const YAML::Node traj_node = doc.root[kTrajectory];
  doc.root.remove(kScene);
  doc.root.remove(kTrajectory);
  doc.root.remove("version");
  if (rig_node.IsMap()) doc.root["rig"].remove("event_camera");
  config::fill(doc, "", o);
  o.sampling.tile_px = o.sampling.tilePx();  // the resolved YAML states the tile in use

  // 3. The trajectory, with the scenario's seed.
  if (!traj_node.IsDefined() || traj_node.IsNull()) throw Error(doc.file + ": trajectory: missing");
  std::string traj_dir;
  std::optional<config::Document> traj_preset;
  config::Document traj_doc = sectionDocument(doc, traj_node, kTrajectory, base_dir, search_root, &traj_dir, &traj_preset);
  if (traj_preset) makeTrajectory(*traj_preset, "");  // errors of the preset alone name its file
  traj_doc.root["seed"] = o.seed;
  // makeTrajectory resolves a relative from_file path against the folder of doc.file.
  if (traj_preset) traj_doc.file = traj_preset->file;
  try {
    s.trajectory = makeTrajectory(traj_doc, "");
  } catch (const Error& e) {
    if (!traj_preset) throw;
    throw Error("trajectory (" + doc.file + " over " + traj_preset->file + "): " + e.what());
  }

  // 4. IMU gravity from the trajectory unless the scenario sets it.
  const YAML::Node imu_node = config::child(doc, "rig.imu");
  if (!imu_node["gravity_mps2"].IsDefined()) {
    const YAML::Node resolved = YAML::Load(s.trajectory->configYaml());
    o.rig.imu.gravity_mps2 = resolved["gravity_mps2"].as<double>();
  }

  // 5. The time window.
  s.start_ns = s.trajectory->startTime() + secondsToNs(o.start_s);
  s.end_ns = s.start_ns + secondsToNs(o.duration_s);
  if (s.end_ns > s.trajectory->endTime())
    throw Error(doc.file + ": start_s + duration_s = " + std::to_string(o.start_s + o.duration_s) +
                " s is past the end of the trajectory (" +
                std::to_string(nsToSeconds(s.trajectory->endTime() - s.trajectory->startTime())) + " s)");

  // 6. The scene.
  if (!scene_node.IsDefined() || scene_node.IsNull()) throw Error(doc.file + ": scene: missing");
  std::string scene_dir;
  std::optional<config::Document> scene_preset;
  config::Document scene_doc = sectionDocument(doc, scene_node, kScene, base_dir, search_root, &scene_dir, &scene_preset);
  if (scene_preset) scenes::loadSceneDocument(*scene_preset, scene_dir);
  s.scene = scenes::loadSceneDocument(scene_doc, scene_dir);

  // Cross-checks that need several sections.
  requireField(!o.rig.frame_camera.enabled || o.rig.frame_camera.name != "cam0", "rig.frame_camera.name",
               "'cam0' is the event camera's name");
  s.eventCamera();
  if (o.rig.frame_camera.enabled) s.frameCamera();
  return s;
}

}  // namespace

Scenario loadScenario(const std::string& path, const std::vector<std::string>& overrides,
                      const std::string& search_root) {
  config::Document doc = config::loadFile(path);
  presetScalarsToMaps(doc, overrides);
  for (const auto& o : overrides) config::applyOverride(doc, o);
  return loadScenarioDocument(doc, fs::path(path).parent_path().string(), search_root);
}

Scenario loadScenarioString(const std::string& text, const std::string& name, const std::string& base_dir,
                            const std::vector<std::string>& overrides, const std::string& search_root) {
  config::Document doc = config::loadString(text, name);
  presetScalarsToMaps(doc, overrides);
  for (const auto& o : overrides) config::applyOverride(doc, o);
  return loadScenarioDocument(doc, base_dir, search_root);
}

std::string Scenario::resolvedYaml() const {
  ScenarioOptions o = options;
  o.rig.event_camera.preset.clear();  // every field is inline
  o.rig.frame_camera.preset.clear();
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << evioVersion();
  out << YAML::Key << "description" << YAML::Value << o.description;
  out << YAML::Key << "seed" << YAML::Value << o.seed;
  out << YAML::Key << "start_s" << YAML::Value;
  config::emitDouble(out, o.start_s);
  out << YAML::Key << "duration_s" << YAML::Value;
  config::emitDouble(out, o.duration_s);
  out << YAML::Key << "scene" << YAML::Value << YAML::Load(config::toYaml(scene.options));
  out << YAML::Key << "trajectory" << YAML::Value << YAML::Load(trajectory->configYaml());
  out << YAML::Key << "rig" << YAML::Value << YAML::Load(config::toYaml(o.rig));
  out << YAML::Key << "sampling" << YAML::Value << YAML::Load(config::toYaml(o.sampling));
  out << YAML::Key << "output" << YAML::Value << YAML::Load(config::toYaml(o.output));
  out << YAML::EndMap;
  return "# The resolved scenario of this sequence (evio simulate; simulator/scenario.h).\n"
         "# `evio simulate scenario.yaml -o <folder>` reproduces the folder byte for byte.\n" +
         std::string(out.c_str()) + "\n";
}

}  // namespace evio::simulator
