#pragma once
/// @file scene_description.h
/// A scene file (YAML): materials, lights, geometry sources and lighting
/// options. Example (see scenes/presets/ for complete ones):
///
///   seed: 7
///   indirect: {bounces: 0}
///   preview: {position_m: [0, -6, 3], look_at_m: [0, 0, 0]}
///   materials:
///     - {name: regolith, model: oren_nayar, roughness_deg: 25,
///        albedo: {type: noise, dust_albedo: 0.27, rock_albedo: 0.13}}
///   lights:
///     - {type: sun, azimuth_deg: 90, elevation_deg: 25, irradiance_w_m2: 590}
///     - {type: sky, radiance_w_m2_sr: 6}
///   sources:
///     - {type: terrain, material: regolith, size_m: [40, 40]}
///
/// Loading rejects unknown keys, unknown types, bad values, duplicate names
/// and dangling references with "file:line: field: message".

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/io/config.h"
#include "evio/scenes/light.h"
#include "evio/scenes/material.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

/// Deterministic indirect light: an irradiance cache on the mesh vertices
/// (scenes/irradiance_cache.h).
struct IndirectOptions {
  int bounces = 0;        ///< 0 = off (sky unoccluded, no inter-reflection)
  int directions = 64;    ///< fixed hemisphere directions per vertex
  template <class V>
  void fields(V& v) {
    v("bounces", bounces, "indirect bounces, 0 = off");
    v("directions", directions, "hemisphere directions per vertex");
  }
  void validate() const {
    requireInRange("bounces", bounces, 0, 8);
    requireInRange("directions", directions, 1, 4096);
  }
};

/// A default viewpoint (for previews and `evio render` without --pose): the
/// camera at position_m looks at look_at_m with image-up close to `up`.
struct PreviewOptions {
  Vec3 position_m = Vec3(0.0, -5.0, 2.0);
  Vec3 look_at_m = Vec3::Zero();
  Vec3 up = Vec3::UnitZ();
  template <class V>
  void fields(V& v) {
    v("position_m", position_m, "camera position (m)");
    v("look_at_m", look_at_m, "point the optical axis goes through (m)");
    v("up", up, "direction that appears up in the image");
  }
  void validate() const;
};

struct SceneOptions {
  std::string description;                 ///< one line for humans
  std::uint64_t seed = 1;                  ///< seeds every procedural generator
  IndirectOptions indirect;
  PreviewOptions preview;
  std::vector<MaterialOptions> materials;
  std::vector<LightOptions> lights;
  std::vector<SourceOptions> sources;

  template <class V>
  void fields(V& v) {
    v("description", description, "one line for humans");
    v("seed", seed, "seed of the procedural generators");
    v("indirect", indirect, "indirect light");
    v("preview", preview, "default viewpoint");
    v("materials", materials, "materials");
    v("lights", lights, "lights");
    v("sources", sources, "geometry sources");
  }
};

/// A loaded scene file: the options plus where everything came from.
struct SceneDescription {
  SceneOptions options;
  std::string file;                        ///< the scene file ("<string>" for text)
  std::string base_dir;                    ///< relative paths are resolved here
  std::vector<std::string> source_where;   ///< "file:line: sources[i]" per source
  std::vector<std::string> material_where; ///< "file:line: materials[i]" per material
  std::vector<std::string> light_where;    ///< "file:line: lights[i]" per light
};

/// Loads and checks a scene file; `overrides` are `--set a.b=value` strings.
SceneDescription loadSceneFile(const std::string& path, const std::vector<std::string>& overrides = {});

/// Parses scene text; relative paths resolve against `base_dir`.
SceneDescription loadSceneString(const std::string& text, const std::string& name = "<string>",
                                 const std::string& base_dir = "");

/// Parses a scene from a YAML document (after overrides).
SceneDescription loadSceneDocument(const config::Document& doc, const std::string& base_dir);

/// The orientation R_W_C of a camera at `position` looking at `target` with
/// image-up along `up` (camera frame: x right, y down, z forward). Throws when
/// target = position or up is parallel to the viewing direction.
Mat3 lookAtRotation(const Vec3& position, const Vec3& target, const Vec3& up);

}  // namespace evio::scenes
