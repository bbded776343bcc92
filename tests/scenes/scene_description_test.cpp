#include "evio/scenes/scene_description.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "evio/core/error.h"

namespace evio::scenes {
namespace {

const char* kMinimal =
    "materials:\n"                                          // 1
    "  - {name: m, albedo: {type: constant, value: 0.5}}\n"  // 2
    "lights:\n"                                             // 3
    "  - {type: sun, azimuth_deg: 0, elevation_deg: 90, irradiance_w_m2: 590}\n"  // 4
    "sources:\n"                                            // 5
    "  - {type: plane, material: m}\n";                     // 6

/// Expects loading `text` to fail with a message containing every part.
void expectError(const std::string& text, std::initializer_list<std::string> parts) {
  try {
    loadSceneString(text, "scene.yaml");
    FAIL() << "expected an error for:\n" << text;
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "missing '" << p << "' in: " << msg;
  }
}

TEST(SceneDescription, MinimalSceneLoadsWithDefaults) {
  const auto d = loadSceneString(kMinimal, "scene.yaml");
  ASSERT_EQ(d.options.sources.size(), 1u);
  EXPECT_EQ(d.options.sources[0].name, "plane0");
  EXPECT_EQ(d.options.materials[0].model, "lambertian");
  EXPECT_EQ(d.options.indirect.bounces, 0);
  EXPECT_EQ(d.source_where[0], "scene.yaml:6: sources[0]");
}

TEST(SceneDescription, EveryPresetLoads) {
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(EVIO_SCENE_PRESET_DIR)) {
    if (entry.path().extension() != ".yaml" || entry.path().stem() == "preview_rig") continue;
    SCOPED_TRACE(entry.path().string());
    const auto d = loadSceneFile(entry.path().string());
    EXPECT_FALSE(d.options.description.empty());
    ++n;
  }
  EXPECT_EQ(n, 6);  // mars_terrain, mars_yard, lava_tube, ec_poster, ec_shapes, ec_boxes
}

TEST(SceneDescription, UnknownSourceTypeIsOneClearError) {
  expectError(std::string(kMinimal) + "  - {type: torus, material: m, radius_m: 2}\n",
              {"scene.yaml:7", "sources[1].type", "unknown source type 'torus'", "known: plane"});
  expectError(std::string(kMinimal) + "  - {material: m}\n", {"scene.yaml:7", "sources[1].type", "missing"});
}

TEST(SceneDescription, UnknownKeysAndTypesAreRejectedWithLine) {
  expectError(std::string(kMinimal) + "  - {type: box, material: m, size_m: [1, 1, 1], radius_m: 2}\n",
              {"scene.yaml:7", "sources[1].radius_m", "unknown key"});
  expectError("materials:\n  - {name: m, albedo: {type: marble}}\nlights: []\nsources: []\n",
              {"scene.yaml:2", "albedo.type", "unknown texture type 'marble'"});
  expectError("materials:\n  - {name: m, model: phong}\n", {"scene.yaml:2", "materials[0].model", "phong"});
  expectError("materials:\n  - {name: m, albedo: {type: constant, value: 0.5, path: x.png}}\n",
              {"scene.yaml:2", "albedo.path", "unknown key"});
  expectError("lights:\n  - {type: laser}\n", {"scene.yaml:2", "lights[0].type", "unknown light type"});
  expectError(std::string(kMinimal) + "colour: red\n", {"scene.yaml:7", "colour", "unknown key"});
}

TEST(SceneDescription, ZeroOrNegativeLightNamesFieldAndLine) {
  std::string text = kMinimal;
  text.replace(text.find("590"), 3, "0");
  expectError(text, {"scene.yaml:4", "lights[0].irradiance_w_m2", "> 0"});
  expectError(std::string(kMinimal).replace(std::string(kMinimal).find("590"), 3, "-5"),
              {"scene.yaml:4", "irradiance_w_m2"});
  const std::string with_sky = std::string(kMinimal).insert(std::string(kMinimal).find("sources:"),
                                                           "  - {type: sky,\n     radiance_w_m2_sr: -1}\n");
  expectError(with_sky, {"scene.yaml:6", "lights[1].radiance_w_m2_sr"});
  const std::string with_point = std::string(kMinimal).insert(
      std::string(kMinimal).find("sources:"), "  - {type: point, position_m: [0, 0, 1], intensity_w_sr: 0}\n");
  expectError(with_point, {"scene.yaml:5", "lights[1].intensity_w_sr"});
}

TEST(SceneDescription, BadValuesAndReferences) {
  expectError(std::string(kMinimal) + "  - {type: box, material: nope}\n",
              {"scene.yaml:7", "sources[1].material", "no material named 'nope'"});
  expectError(std::string(kMinimal) + "  - {type: plane, name: plane0, material: m}\n",
              {"sources[1].name", "duplicate"});
  expectError(std::string(kMinimal) + "  - {type: plane, material: m, size_m: [1, -2]}\n",
              {"scene.yaml:7", "sources[1].size_m[1]"});
  expectError(std::string(kMinimal) + "  - {type: rocks, material: m, ground: plane0}\n",
              {"sources[1].ground", "rocks rest on"});
  expectError(std::string(kMinimal) + "  - {type: rocks, material: m, ground: later}\n",
              {"sources[1].ground", "no earlier source"});
  expectError(std::string(kMinimal) + "  - {type: mesh, material: m}\n", {"sources[1].path", "required"});
  expectError("materials: []\nlights: []\nsources: []\n", {"materials", "at least one"});
}

TEST(SceneDescription, OverridesAndYamlRoundTrip) {
  auto doc = config::loadString(kMinimal, "scene.yaml");
  config::applyOverride(doc, "seed=99");
  const auto d = loadSceneDocument(doc, "");
  EXPECT_EQ(d.options.seed, 99u);
  // The resolved options print and read back to the same options.
  const auto again = loadSceneString(config::toYaml(d.options), "resolved.yaml");
  EXPECT_TRUE(config::equal(d.options, again.options)) << config::toYaml(d.options);
}

TEST(SceneDescription, LookAtRotation) {
  const Mat3 R = lookAtRotation(Vec3(0, -1, 0), Vec3(0, 0, 0), Vec3::UnitZ());
  // Looking along +y with z up: x_C = +x_W, y_C = -z_W, z_C = +y_W.
  EXPECT_NEAR((R.col(0) - Vec3::UnitX()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((R.col(1) + Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((R.col(2) - Vec3::UnitY()).norm(), 0.0, 1e-15);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
  EXPECT_THROW(lookAtRotation(Vec3::Zero(), Vec3(0, 0, 1), Vec3::UnitZ()), Error);
}

}  // namespace
}  // namespace evio::scenes
