#include "evio/simulator/render_job.h"

#include <filesystem>
#include <sstream>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/stopwatch.h"
#include "evio/core/version.h"
#include "evio/simulator/render_output.h"

namespace evio::simulator {

Pose previewPose(const scenes::SceneDescription& description) {
  const auto& p = description.options.preview;
  return Pose(scenes::lookAtRotation(p.position_m, p.look_at_m, p.up), p.position_m);
}

RenderJobReport runRenderJob(const RenderJob& job) {
  const SensorRig rig = io::readSensorsYaml(job.rig_file);
  const CameraSensor* sensor = job.camera_name.empty() ? &rig.cameras.front() : rig.findCamera(job.camera_name);
  if (!sensor) throw Error::inField(job.rig_file, 0, "cameras", "no camera named '" + job.camera_name + "'");

  const scenes::SceneDescription description = scenes::loadSceneFile(job.scene_file, job.scene_overrides);
  scenes::SceneBuildOptions build;
  build.threads = job.build_threads;
  const scenes::Scene scene(description, build);

  RenderJobReport report;
  report.stats = scene.stats();
  report.T_W_C = job.T_W_C ? *job.T_W_C : previewPose(description);
  const Renderer renderer(scene, sensor->camera, job.renderer);
  const Stopwatch watch;
  const RenderOutput out = renderer.render(report.T_W_C, job.velocity ? &*job.velocity : nullptr);
  report.render_s = watch.seconds();

  const double white = job.white_w_m2_sr > 0.0 ? job.white_w_m2_sr : autoWhite(out.radiance);
  report.files = writeRenderOutput(job.out_dir, out, white);

  // The resolved settings, beside the images.
  std::ostringstream s;
  s.precision(17);
  const Pose& T = report.T_W_C;
  s << "# written by " << evioVersion() << " (evio render)\n";
  s << "scene_file: \"" << job.scene_file << "\"\n";
  s << "rig_file: \"" << job.rig_file << "\"\n";
  s << "camera: \"" << sensor->name << "\"\n";
  s << "pose_T_W_C: [" << T.translation().x() << ", " << T.translation().y() << ", " << T.translation().z()
    << ", " << T.quaternion().x() << ", " << T.quaternion().y() << ", " << T.quaternion().z() << ", "
    << T.quaternion().w() << "]  # px py pz qx qy qz qw\n";
  if (job.velocity)
    s << "velocity: {v_C: [" << job.velocity->v_C.x() << ", " << job.velocity->v_C.y() << ", "
      << job.velocity->v_C.z() << "], omega_C: [" << job.velocity->omega_C.x() << ", "
      << job.velocity->omega_C.y() << ", " << job.velocity->omega_C.z() << "]}\n";
  s << "preview_white_w_m2_sr: " << white << "\n";
  s << "renderer:\n";
  std::istringstream renderer_yaml(config::toYaml(job.renderer));
  for (std::string line; std::getline(renderer_yaml, line);) s << "  " << line << "\n";
  s << "scene:\n";
  std::istringstream scene_yaml(config::toYaml(description.options));
  for (std::string line; std::getline(scene_yaml, line);) s << "  " << line << "\n";
  const std::string yaml_path = (std::filesystem::path(job.out_dir) / "render.yaml").string();
  io::writeFileAtomic(yaml_path, s.str());
  report.files.push_back(yaml_path);
  return report;
}

}  // namespace evio::simulator
