#pragma once
/// @file render_job.h
/// The work behind `evio render <scene.yaml> --camera <sensors.yaml> ...`:
/// load the scene, build it, render one view, write the images and the
/// resolved settings (render.yaml) into the output folder.

#include <optional>
#include <string>
#include <vector>

#include "evio/core/pose.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/renderer.h"

namespace evio::simulator {

struct RenderJob {
  std::string scene_file;                  ///< scene YAML
  std::vector<std::string> scene_overrides;///< "a.b=value" applied to the scene file
  std::string rig_file;                    ///< sensors.yaml holding the camera
  std::string camera_name;                 ///< camera of the rig; "" = the first one
  std::optional<Pose> T_W_C;               ///< camera pose; default: the scene's preview viewpoint
  std::optional<CameraVelocity> velocity;  ///< when set, flow.exr is written too
  std::string out_dir;                     ///< output folder
  RendererOptions renderer;
  int build_threads = 0;                   ///< scene build threads, 0 = all cores
  double white_w_m2_sr = 0.0;              ///< preview white level, 0 = auto
};

struct RenderJobReport {
  scenes::SceneStats stats;                ///< scene build timings and sizes
  double render_s = 0.0;                   ///< wall-clock time of the render
  Pose T_W_C;                              ///< the pose used
  std::vector<std::string> files;          ///< files written
};

/// The scene's preview viewpoint (scene_description.h, PreviewOptions) as T_W_C.
Pose previewPose(const scenes::SceneDescription& description);

/// Runs the job. Throws evio::Error (file, line, field) for bad input.
RenderJobReport runRenderJob(const RenderJob& job);

}  // namespace evio::simulator
