// Scenario loading (scenario.h): every shipped scenario loads and its
// resolved form round-trips; presets, merges, overrides and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "evio/core/error.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/renderer.h"
#include "evio/simulator/scenario.h"
#include "error_of.h"

namespace evio::simulator {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string>& shippedScenarios() {
  static const std::vector<std::string> names = {
      "mars_yard_circle", "lava_tube_entry",  "mars_hover",     "mars_rotation",
      "mars_flight",      "poster_6dof",      "poster_translation", "poster_rotation",
      "shapes_6dof",      "shapes_rotation",  "boxes_6dof",     "boxes_rotation"};
  return names;
}

std::string scenarioPath(const std::string& name) {
  return std::string(EVIO_SOURCE_DIR) + "/experiments/scenarios/" + name + ".yaml";
}

using test::errorOf;

TEST(Scenario, EveryShippedScenarioLoadsAndItsResolvedFormRoundTrips) {
  for (const auto& name : shippedScenarios()) {
    SCOPED_TRACE(name);
    const Scenario s = loadScenario(scenarioPath(name), {}, EVIO_SOURCE_DIR);
    EXPECT_FALSE(s.options.description.empty());
    EXPECT_GT(s.end_ns, s.start_ns);
    EXPECT_LE(s.end_ns, s.trajectory->endTime());
    const SensorRig rig = s.sensorRig();
    EXPECT_EQ(rig.cameras.front().role, CameraRole::kEvent);
    // The camera looks at the scene: its optical axis at the start points
    // down or ahead, never up into the sky.
    const Pose T_W_E = s.trajectory->evaluate(s.start_ns).T_W_B * s.T_B_E();
    EXPECT_LT(T_W_E.rotation().col(2).z(), 0.1);
    // Resolved YAML: loading it gives the same resolved YAML.
    const std::string resolved = s.resolvedYaml();
    const Scenario again = loadScenarioString(resolved, name + " (resolved)", "", {}, EVIO_SOURCE_DIR);
    EXPECT_EQ(again.resolvedYaml(), resolved);
  }
}

TEST(Scenario, ShippedDefaultsArePhysicallySensible) {
  const Scenario yard = loadScenario(scenarioPath("mars_yard_circle"), {}, EVIO_SOURCE_DIR);
  EXPECT_EQ(yard.options.rig.event_camera.sensor.width, 346);  // DAVIS346 from the preset
  EXPECT_EQ(yard.options.rig.imu.gravity_mps2, 9.81);          // the Mars Yard is on Earth
  EXPECT_LE(yard.options.duration_s, 10.0);                    // short: the main job runs it
  const Scenario hover = loadScenario(scenarioPath("mars_hover"), {}, EVIO_SOURCE_DIR);
  EXPECT_EQ(hover.options.rig.imu.gravity_mps2, 3.721);        // Mars, from the trajectory
  EXPECT_TRUE(hover.sensorRig().range_finder.has_value());
  const Scenario poster = loadScenario(scenarioPath("poster_6dof"), {}, EVIO_SOURCE_DIR);
  EXPECT_EQ(poster.eventCamera().model(), "radtan");
  EXPECT_EQ(poster.eventCamera().width(), 240);
}

TEST(Scenario, OverridesReachPresetSections) {
  const Scenario s = loadScenario(scenarioPath("mars_yard_circle"),
                                  {"duration_s=2", "seed=5", "trajectory.diameter_m=2.5",
                                   "rig.event_camera.event_camera.threshold_pos=0.3", "scene.seed=9"},
                                  EVIO_SOURCE_DIR);
  EXPECT_EQ(s.end_ns - s.start_ns, 2 * kNsPerSecond);
  EXPECT_EQ(s.options.rig.event_camera.sensor.event_camera.threshold_pos, 0.3);
  EXPECT_EQ(s.options.rig.event_camera.sensor.event_camera.threshold_neg, 0.38);  // kept from the preset
  EXPECT_EQ(s.scene.options.seed, 9u);
  const std::string yaml = s.resolvedYaml();
  EXPECT_NE(yaml.find("diameter_m: 2.5"), std::string::npos);
  EXPECT_NE(yaml.find("seed: 5"), std::string::npos);  // the trajectory takes the scenario's seed
  EXPECT_EQ(yaml.find("\nthreads:"), std::string::npos) << "threads never change the output";
}

TEST(Scenario, TileEdgeDefaultsBySchedule) {
  // tile_px 0 (the default): 16 px for whole frames (their events depend
  // slightly on the renderer's tile, so it stays what it was), 8 px for the
  // tile schedule; the resolved YAML states the tile in use, and a tile set
  // explicitly is kept with either schedule.
  const auto tile = [](const std::vector<std::string>& overrides) {
    const Scenario s = loadScenario(scenarioPath("mars_yard_circle"), overrides, EVIO_SOURCE_DIR);
    EXPECT_EQ(s.options.sampling.tilePx(), s.options.sampling.tile_px);
    EXPECT_NE(s.resolvedYaml().find("tile_px: " + std::to_string(s.options.sampling.tile_px)), std::string::npos);
    return s.options.sampling.tile_px;
  };
  EXPECT_EQ(tile({}), 16);
  EXPECT_EQ(tile({"sampling.schedule=tiles"}), 8);
  EXPECT_EQ(tile({"sampling.schedule=tiles", "sampling.tile_px=16"}), 16);
  EXPECT_EQ(tile({"sampling.tile_px=4"}), 4);
  RenderScheduleOptions unresolved;  // built in code, not loaded
  EXPECT_EQ(unresolved.tilePx(), 16);
  unresolved.schedule = "tiles";
  EXPECT_EQ(unresolved.tilePx(), 8);
}

TEST(Scenario, BadInputNamesFileLineAndField) {
  const std::string base = R"(
scene: scenes/presets/ec_shapes.yaml
trajectory: trajectories/presets/hover.yaml
rig:
  event_camera: {preset: simulator/presets/davis240c.yaml}
)";
  const auto load = [&](const std::string& extra) {
    return errorOf([&] { loadScenarioString(base + extra, "bad.yaml", "", {}, EVIO_SOURCE_DIR); });
  };
  EXPECT_EQ(load(""), "");
  std::string e = load("  imu: {bogus_key: 1}\n");
  EXPECT_NE(e.find("bad.yaml:6"), std::string::npos) << e;
  EXPECT_NE(e.find("bogus_key"), std::string::npos) << e;
  e = load("duration_s: -1\n");
  EXPECT_NE(e.find("duration_s"), std::string::npos) << e;
  e = load("sampling: {schedule: tile}\n");
  EXPECT_NE(e.find("sampling.schedule"), std::string::npos) << e;
  EXPECT_NE(e.find("whole_frame or tiles"), std::string::npos) << e;
  e = load("sampling: {tile_px: -1}\n");
  EXPECT_NE(e.find("sampling.tile_px"), std::string::npos) << e;
  EXPECT_NE(e.find("0 (by schedule)"), std::string::npos) << e;
  e = load("sampling: {tile_quantum_s: 1}\n");
  EXPECT_NE(e.find("tile_quantum_s"), std::string::npos) << e;
  e = load("duration_s: 100\n");  // the hover preset lasts 60 s
  EXPECT_NE(e.find("past the end of the trajectory"), std::string::npos) << e;
  e = load("  frame_camera: {rate_hz: 20, sensor: {auto_exposure: false, exposure_s: 0.04, readout_s: 0.02}}\n");
  EXPECT_NE(e.find("sensor.exposure_s"), std::string::npos) << e;
  e = load("  frame_camera: {preset: simulator/presets/aps_davis240c.yaml, rate_hz: 24}\n");  // 5 + 41 ms > 1/24 s
  EXPECT_NE(e.find("sensor.exposure_s"), std::string::npos) << e;
  e = load("  frame_camera: {preset: simulator/presets/aps_davis240c.yaml, sensor: {shutter: diagonal}}\n");
  EXPECT_NE(e.find("shutter"), std::string::npos) << e;
  e = load("  frame_camera: {preset: simulator/presets/no_such_aps.yaml}\n");
  EXPECT_NE(e.find("no_such_aps.yaml"), std::string::npos) << e;
  e = errorOf([&] {
    loadScenarioString(base + "  range_finder: {enabled: true, T_B_L: [1,0,0,0, 0,1,0,0, 0,0,2,0, 0,0,0,1]}\n",
                       "bad.yaml", "", {}, EVIO_SOURCE_DIR);
  });
  EXPECT_NE(e.find("T_B_L"), std::string::npos) << e;
  e = errorOf([&] { loadScenarioString("scene: nowhere.yaml\ntrajectory: trajectories/presets/hover.yaml\n",
                                       "bad.yaml", "", {}, EVIO_SOURCE_DIR); });
  EXPECT_NE(e.find("nowhere.yaml"), std::string::npos) << e;
  e = errorOf([&] {
    loadScenarioString("scene: scenes/presets/ec_shapes.yaml\ntrajectory: trajectories/presets/hover.yaml\n",
                       "bad.yaml", "", {}, EVIO_SOURCE_DIR);
  });
  EXPECT_NE(e.find("resolution"), std::string::npos) << e;  // no event sensor given
  e = errorOf([&] {
    loadScenarioString(base + "  event_camera: {preset: simulator/presets/davis240c.yaml, model: equidistant}\n",
                       "bad.yaml", "", {}, EVIO_SOURCE_DIR);
  });
  EXPECT_FALSE(e.empty());
}

TEST(Scenario, FrameCameraPresetLiesUnderTheScenariosKeys) {
  const std::string text = R"(
scene: scenes/presets/ec_shapes.yaml
trajectory: trajectories/presets/hover.yaml
rig:
  event_camera: {preset: simulator/presets/davis240c.yaml}
  frame_camera:
    preset: simulator/presets/aps_davis240c.yaml
    rate_hz: 20
    sensor: {exposure_s: 0.003}
)";
  const Scenario s = loadScenarioString(text, "s.yaml", "", {"rig.frame_camera.sensor.shutter=rolling"}, EVIO_SOURCE_DIR);
  const auto& sensor = s.options.rig.frame_camera.sensor;
  EXPECT_EQ(sensor.exposure_s, 0.003);       // the scenario's key
  EXPECT_EQ(sensor.shutter, "rolling");      // the override
  EXPECT_EQ(sensor.full_well_e, 10350.0);    // the preset's
  EXPECT_EQ(sensor.dark_offset_dn, -16.7);
  EXPECT_FALSE(sensor.auto_exposure);
  // The resolved scenario holds every sensor key inline and no preset.
  const std::string yaml = s.resolvedYaml();
  EXPECT_NE(yaml.find("saturation_dn: 131.3"), std::string::npos);
  const Scenario again = loadScenarioString(yaml, "resolved.yaml", "", {}, EVIO_SOURCE_DIR);
  EXPECT_EQ(again.options.rig.frame_camera.sensor.full_well_e, 10350.0);
  EXPECT_EQ(again.options.rig.frame_camera.sensor.shutter, "rolling");
  EXPECT_TRUE(again.options.rig.frame_camera.preset.empty());
}

TEST(Scenario, InlineSectionsNeedNoPresetFiles) {
  const char* text = R"(
duration_s: 1
scene:
  lights: [{type: sky, radiance_w_m2_sr: 2}]
  materials: [{name: m, model: lambertian, albedo: {type: constant, value: 0.5}}]
  sources: [{type: plane, name: floor, material: m, size_m: [10, 10]}]
trajectory: {type: hover, duration_s: 5, center_m: [0, 0, 2]}
rig:
  event_camera: {name: tiny, width: 32, height: 24, intrinsics: [30, 30, 15.5, 11.5], pixel_pitch_um: 10}
)";
  const Scenario s = loadScenarioString(text, "inline.yaml", "", {}, "");
  EXPECT_EQ(s.eventCamera().width(), 32);
  EXPECT_EQ(s.scene.options.sources.size(), 1u);
  EXPECT_EQ(s.options.rig.imu.gravity_mps2, 3.721);  // hover's default gravity
}

}  // namespace
}  // namespace evio::simulator

namespace evio::simulator {
namespace {

/// The camera at a quarter of the resolution (same field of view).
Camera quarter(const Camera& c) {
  const Vec4 k = c.intrinsics();
  const Vec4 q(k[0] / 4, k[1] / 4, (k[2] + 0.5) / 4 - 0.5, (k[3] + 0.5) / 4 - 0.5);
  return Camera::create(c.model(), c.width() / 4, c.height() / 4, q, c.distortion());
}

TEST(Scenario, EveryShippedScenarioSeesTextureAtStartMiddleAndEnd) {
  for (const auto& name : shippedScenarios()) {
    SCOPED_TRACE(name);
    // Indirect light off: the geometry is the same, the build takes no time.
    const Scenario s = loadScenario(scenarioPath(name), {"scene.indirect.bounces=0"}, EVIO_SOURCE_DIR);
    const scenes::Scene scene(s.scene);
    const Renderer renderer(scene, quarter(s.eventCamera()));
    for (const TimeNs t : {s.start_ns, (s.start_ns + s.end_ns) / 2, s.end_ns}) {
      const RenderOutput out = renderer.render(s.trajectory->evaluate(t).T_W_B * s.T_B_E());
      int surface = 0, lit = 0;
      double sum = 0.0, sum2 = 0.0;
      const int n = out.depth.rows * out.depth.cols;
      for (int y = 0; y < out.depth.rows; ++y)
        for (int x = 0; x < out.depth.cols; ++x) {
          const float z = out.depth.at<float>(y, x), r = out.radiance.at<float>(y, x);
          surface += std::isfinite(z) && z > 0.0f;
          lit += r > 0.0f;
          const double l = std::log(1e-3 + static_cast<double>(std::max(r, 0.0f)));
          sum += l;
          sum2 += l * l;
        }
      // Most of the view is the scene (ec_boxes' room is open at the sides:
      // at the end of boxes_6dof, yawed 30 deg, about 11 % of the view passes it).
      EXPECT_GT(surface, 0.8 * n) << "t = " << nsToSeconds(t) << " s: the camera sees the scene";
      EXPECT_GT(lit, 0.8 * n) << "t = " << nsToSeconds(t) << " s";
      const double mean = sum / n;
      EXPECT_GT(std::sqrt(std::max(0.0, sum2 / n - mean * mean)), 0.05) << "t = " << nsToSeconds(t) << " s: texture";
    }
  }
}

}  // namespace
}  // namespace evio::simulator
