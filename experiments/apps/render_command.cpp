// `evio render <scene.yaml> --camera <sensors.yaml> [--pose ...] -o <folder>`:
// renders one HDR view of a scene (radiance and depth EXR, tone-mapped PNG).
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "data_root.h"
#include "evio/core/error.h"
#include "evio/core/io/staged_folder.h"
#include "evio/simulator/render_job.h"

namespace evio::apps {

namespace {

std::vector<double> numbers(const std::string& text, std::size_t count, const char* option) {
  std::string t = text;
  for (auto& c : t)
    if (c == ',') c = ' ';
  std::istringstream s(t);
  std::vector<double> v;
  double x;
  while (s >> x) v.push_back(x);
  if (!s.eof() || v.size() != count)
    throw Error(std::string(option) + ": expected " + std::to_string(count) + " numbers, got '" + text + "'");
  return v;
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  struct Args {
    simulator::RenderJob job;
    std::string pose, look_at, velocity;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("render", "Render one HDR view of a scene (radiance/depth EXR, PNG preview)");
  cmd->add_option("scene", args->job.scene_file, "scene YAML (e.g. scenes/presets/mars_yard.yaml)")->required();
  cmd->add_option("--camera", args->job.rig_file, "sensors.yaml holding the camera")->required();
  cmd->add_option("--camera-name", args->job.camera_name, "camera of the rig (default: the first)");
  cmd->add_option("--pose", args->pose,
                  "camera pose T_W_C as 'px py pz qx qy qz qw' (TUM order; default: the scene's preview)");
  cmd->add_option("--look-at", args->look_at, "camera pose as 'px py pz tx ty tz' (z up in the image)");
  cmd->add_option("--velocity", args->velocity,
                  "camera velocity in C 'vx vy vz wx wy wz' (m/s, rad/s): also write flow.exr");
  cmd->add_option("-o,--output", args->job.out_dir, "output folder")->required();
  cmd->add_option("--set", args->job.scene_overrides, "override a scene key: a.b=value (repeatable)");
  cmd->add_option("--threads", args->job.renderer.threads, "render threads (0: all cores)");
  cmd->add_option("--supersampling", args->job.renderer.supersampling, "n x n radiance rays per pixel");
  cmd->add_option("--white", args->job.white_w_m2_sr, "preview white level, W/(m^2 sr) (0: auto)");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    auto& job = args->job;
    job.scene_file = resolveDataPath(job.scene_file);
    if (!args->pose.empty() && !args->look_at.empty()) throw Error("--pose and --look-at are exclusive");
    if (!args->pose.empty()) {
      const auto v = numbers(args->pose, 7, "--pose");
      const Quat q(v[6], v[3], v[4], v[5]);
      if (!(q.norm() > 0.0)) throw Error("--pose: the quaternion is zero");
      job.T_W_C = Pose(q, Vec3(v[0], v[1], v[2]));
    }
    if (!args->look_at.empty()) {
      const auto v = numbers(args->look_at, 6, "--look-at");
      const Vec3 p(v[0], v[1], v[2]);
      job.T_W_C = Pose(scenes::lookAtRotation(p, Vec3(v[3], v[4], v[5]), Vec3::UnitZ()), p);
    }
    if (!args->velocity.empty()) {
      const auto v = numbers(args->velocity, 6, "--velocity");
      job.velocity = simulator::CameraVelocity{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])};
    }
    const std::string target = job.out_dir;
    io::StagedFolder out(target);  // published whole at the end, or not at all
    job.out_dir = out.path();
    const auto report = simulator::runRenderJob(job);
    out.publish();
    job.out_dir = target;
    if (args->quiet) return;
    std::printf("scene: %zu triangles, %zu vertices; build %.3f s (generate %.3f, BVH %.3f, indirect %.3f)\n",
                report.stats.triangles, report.stats.vertices, report.stats.total_s(), report.stats.generate_s,
                report.stats.bvh_s, report.stats.indirect_s);
    std::printf("render: %.3f s\n", report.render_s);
    for (const auto& f : report.files)
      std::printf("wrote %s\n", f.rfind(out.path(), 0) == 0 ? (target + f.substr(out.path().size())).c_str() : f.c_str());
  });
}

}  // namespace evio::apps
