// The lava tube: light reaches the inside only through the mouth, by bounce
// where the sun does not reach, and a static scene renders identically.
// Geometry: the sun (40° above the west) lights the eastern 9 m of the 20 m
// pit's floor and enters the 5.5 m high mouth down to ~6.5 m inside; the
// camera looks at the tube's far end (x 12–16 m), which no sunray reaches.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "evio/scenes/lava_tube.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/renderer.h"

namespace evio::simulator {
namespace {

std::string tubeScene(int bounces) {
  return "seed: 2\n"
         "indirect: {bounces: " + std::to_string(bounces) + ", directions: 64}\n"
         "materials:\n  - {name: rock, albedo: {type: noise}}\n"
         "lights:\n  - {type: sun, azimuth_deg: 265, elevation_deg: 40, irradiance_w_m2: 590}\n"
         "sources:\n"
         "  - {type: tube, name: tube, material: rock, length_m: 16, pit_length_m: 20, pit_width_m: 10,\n"
         "     surface_height_m: 9, margin_m: 2, cell_m: 0.5}\n";
}

bool bitEqual(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

TEST(LavaTubeRender, DeepInsideOnlyBounceLightAndRendersIdentically) {
  scenes::SceneBuildOptions one;
  one.threads = 1;
  scenes::SceneBuildOptions two;
  two.threads = 2;
  const scenes::Scene lit(scenes::loadSceneString(tubeScene(2), "tube.yaml"), one);
  const scenes::Scene lit2(scenes::loadSceneString(tubeScene(2), "tube.yaml"), two);
  const scenes::Scene direct_only(scenes::loadSceneString(tubeScene(0), "tube.yaml"));
  const Camera cam = PinholeCamera(48, 36, Vec4(30, 30, 23.5, 17.5));
  // Deep inside, looking further in (away from the mouth): no direct sun.
  const Vec3 c(8.0, 0.0, 2.0);
  const Pose T(scenes::lookAtRotation(c, Vec3(16.0, 0.0, 1.5), Vec3::UnitZ()), c);
  RendererOptions o1, o2;
  o1.threads = 1;
  o2.threads = 2;
  const RenderOutput a = Renderer(lit, cam, o1).render(T);
  const RenderOutput b = Renderer(lit, cam, o2).render(T);
  const RenderOutput again = Renderer(lit, cam, o1).render(T);
  const RenderOutput other_build = Renderer(lit2, cam, o2).render(T);
  EXPECT_TRUE(bitEqual(a.radiance, b.radiance));
  EXPECT_TRUE(bitEqual(a.radiance, again.radiance));
  EXPECT_TRUE(bitEqual(a.radiance, other_build.radiance));
  const RenderOutput dark = Renderer(direct_only, cam, o1).render(T);
  int surface = 0;
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      if (!std::isfinite(a.depth.at<float>(y, x))) continue;
      ++surface;
      EXPECT_EQ(dark.radiance.at<float>(y, x), 0.0f);  // no sun, no sky reaches here directly
      EXPECT_GT(a.radiance.at<float>(y, x), 0.0f) << x << "," << y << " depth " << a.depth.at<float>(y, x);  // bounced sunlight
    }
  EXPECT_EQ(surface, cam.width() * cam.height());  // the tube is closed ahead
}

}  // namespace
}  // namespace evio::simulator
