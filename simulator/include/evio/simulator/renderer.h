#pragma once
/// @file renderer.h
/// The HDR renderer: per-pixel radiance (W/(m²·sr)), depth, surface normal
/// and motion field of a scenes::Scene seen by a core camera model at a pose.
///
/// Rays: pixel (x, y) is the point uv = (x, y) (pixel centres at integer
/// coordinates, camera_common.h); its ray leaves the camera centre along
/// R_W_C · b with b = camera.unproject(uv) (distortion included). The bearing
/// table is computed once per Renderer. With supersampling n > 1 the
/// radiance is the mean over n × n rays at uv + ((i + ½)/n − ½, (j + ½)/n − ½);
/// depth, normal and flow always come from the centre ray.
///
/// Tracing: the image is cut into square tiles processed in parallel; each
/// tile sends its camera rays to Embree as one stream (rtcIntersect1M with
/// the coherent flag), then one stream of occlusion rays (rtcOccluded1M), one
/// per hit and shadow light; shading follows scene.h. Every pixel depends on
/// nothing but its own rays, so the output is bit-identical whatever the
/// number of threads. On a CPU with AVX2 the tile is shaded eight rays at a
/// time (renderer_avx2.cpp, scene_avx2.cpp), with the same float operations
/// in the same order as the scalar path: the output is bit-identical with or
/// without it (RendererOptions::avx2).

#include <cstdint>
#include <memory>
#include <optional>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/core/options.h"
#include "evio/core/pose.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/motion_field.h"

namespace evio::simulator {

struct RendererOptions {
  int threads = 0;           ///< render threads, 0 = all cores (output does not depend on it)
  int tile_px = 16;          ///< tile edge length in pixels
  int supersampling = 1;     ///< n: n × n radiance rays per pixel
  bool check_viewpoint = true;  ///< throw when the camera is inside a solid source
  /// Shade with the AVX2 code path when the CPU has it. Both paths do the
  /// same float operations in the same order (no FMA), so the output is the
  /// same bit for bit; off forces the baseline x86-64 path (tests, timing).
  bool avx2 = true;

  template <class V>
  void fields(V& v) {
    v("threads", threads, "render threads, 0 = all cores");
    v("tile_px", tile_px, "tile edge length (px)");
    v("supersampling", supersampling, "n x n radiance rays per pixel");
    v("check_viewpoint", check_viewpoint, "error when the camera is inside geometry");
    v("avx2", avx2, "use the AVX2 shading path when the CPU has it (same output)");
  }
  void validate() const {
    requireInRange("threads", threads, 0, 1024);
    requireInRange("tile_px", tile_px, 1, 256);
    requireInRange("supersampling", supersampling, 1, 8);
  }
};

/// One rendered view. Images are width × height of the camera.
struct RenderOutput {
  cv::Mat radiance;  ///< CV_32FC1, W/(m²·sr); sky radiance for upward rays that leave the scene
  cv::Mat depth;     ///< CV_32FC1, z of the surface point in C (m, along the optical axis);
                     ///< +inf where the ray leaves the scene; NaN where the pixel has no ray
  cv::Mat normal;    ///< CV_32FC3, unit shading normal in W facing the camera; 0 where no surface
  cv::Mat flow;      ///< CV_32FC2, (u̇, v̇) in px/s (motion_field.h); empty without a velocity
};

/// Ray counts of one render (for throughput figures).
struct RenderStats {
  std::uint64_t camera_rays = 0;  ///< primary rays traced (inactive ones excluded)
  std::uint64_t shadow_rays = 0;  ///< occlusion rays traced
};

class Renderer {
 public:
  /// Keeps references to `scene` (which must outlive the renderer); copies the camera.
  Renderer(const scenes::Scene& scene, const Camera& camera, const RendererOptions& options = {});

  /// Renders the view from T_W_C (camera C in world W). With `velocity`, also
  /// the motion field; with `stats`, the ray counts. Throws Error (naming the
  /// source) when check_viewpoint is on and the camera is inside a solid source.
  RenderOutput render(const Pose& T_W_C, const CameraVelocity* velocity = nullptr,
                      RenderStats* stats = nullptr) const;

  /// The same, into *out: its images are reused when they already have the
  /// right size and type and are not shared with another cv::Mat (else
  /// reallocated), which saves the page faults of fresh images per render.
  /// out->flow is released without a velocity.
  void render(const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out,
              RenderStats* stats = nullptr) const;

  /// The tiles the image is cut into: squares of options().tile_px pixels
  /// (narrower in the last column and row), numbered row-major from the
  /// top-left corner; tile k covers tileRect(k) = [x0, x1) × [y0, y1).
  int tilesX() const { return (camera_.width() + options_.tile_px - 1) / options_.tile_px; }
  int tileCount() const { return tilesX() * ((camera_.height() + options_.tile_px - 1) / options_.tile_px); }
  cv::Rect tileRect(int tile) const;

  /// Re-traces only the tiles tiles[0 .. count) (each in [0, tileCount()),
  /// no repeats) into *out, which must hold the images of an earlier render
  /// of this camera (flow too when `velocity` is given; throws otherwise).
  /// Every pixel of those tiles gets the same bits as render() at T_W_C
  /// would give it; the other pixels keep their values. An image that is
  /// shared with another cv::Mat is copied first (the other keeps its pixels).
  /// `stats` counts the rays of these tiles.
  void renderTiles(const Pose& T_W_C, const CameraVelocity* velocity, const int* tiles, std::size_t count,
                   RenderOutput* out, RenderStats* stats = nullptr) const;

  /// Unit bearing in C of the centre ray of pixel (x, y); NaN when the model
  /// cannot unproject that pixel.
  Eigen::Vector3f bearing(int x, int y) const {
    return bearings_[static_cast<std::size_t>(y) * static_cast<std::size_t>(camera_.width()) +
                     static_cast<std::size_t>(x)];
  }

  const Camera& camera() const { return camera_; }
  const RendererOptions& options() const { return options_; }

 private:
  struct Scratch;
  struct ScratchPool;  ///< per-thread Scratch, kept from render to render
  /// Renders tiles[0 .. count) (nullptr: tiles 0 .. count) in parallel into
  /// *out, whose images have the right size and type.
  void renderTileList(const Pose& T_W_C, const CameraVelocity* velocity, const int* tiles, std::size_t count,
                      RenderOutput* out, RenderStats* stats) const;
  void renderTile(int tile, const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out,
                  RenderStats* counts, Scratch* scratch) const;
  /// renderTile compiled for AVX2 (called only when avx2_).
  void renderTileAvx2(int tile, const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out,
                      RenderStats* counts, Scratch* scratch) const;
  /// The AVX2 copy's albedo pass with supersampling (renderer.cpp; without
  /// supersampling shadePacketsAvx2 does all the shading).
  template <class Shaded, class Footprint>
  void albedoPassAvx2(std::size_t rays, const Shaded& shaded, const Footprint& footprint, Scratch* scratch) const;
  /// The AVX2 copy's shading without supersampling (renderer_avx2.cpp):
  /// surface, albedo, lights, occlusion and radiance of the tile's rays
  /// eight at a time, into scratch->radiance and scratch->columns; returns
  /// the number of occlusion rays traced.
  std::uint64_t shadePacketsAvx2(std::size_t rays, float footprint_scale, Scratch* scratch) const;
  /// The camera rays of tile `tile` (`rays` of them) for shadePacketsAvx2,
  /// directions also as columns, padded to whole groups of eight with rays
  /// that are not traced; returns the number of active rays.
  std::uint64_t setupRaysAvx2(int tile, std::size_t rays, const Eigen::Matrix3f& R, const Eigen::Vector3f& org,
                              Scratch* scratch) const;
  /// The output images of a tile from shadePacketsAvx2's results.
  void writeOutputs(int x0, int y0, int x1, int y1, const CameraVelocity* velocity, RenderOutput* out,
                    const Scratch& scratch) const;
  /// The flow (px/s) of a pixel with unit bearing b (C): of the surface point
  /// at `range` (m) along it when `hit`, else of the direction. False where
  /// the camera cannot project it. Pinhole cameras take PinholeFlow (same bits).
  bool pixelFlow(const Eigen::Vector3f& b, bool hit, float range, const CameraVelocity& velocity, Vec2* f) const {
    const Vec3 bd = b.cast<double>();
    if (pinhole_flow_)
      return hit ? pinhole_flow_->point(bd * static_cast<double>(range), velocity, f)
                 : pinhole_flow_->direction(bd, velocity, f);
    return hit ? pointFlow(camera_, bd * static_cast<double>(range), velocity, f) : directionFlow(camera_, bd, velocity, f);
  }
  /// The flow of the pixels [x0, x1) of row y, whose rays are scratch's
  /// r0, r0 + 1, ...: four at a time in double for a pinhole camera (the
  /// bits of pixelFlow, renderer_avx2.cpp), pixel by pixel otherwise.
  void flowRowAvx2(int y, int x0, int x1, std::size_t r0, const CameraVelocity& velocity, cv::Vec2f* flow,
                   const Scratch& scratch) const;
  /// The body of both, inlined into each.
  template <bool kAvx2>
  void shadeTile(int tile, const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out,
                 RenderStats* counts, Scratch* scratch) const;

  const scenes::Scene& scene_;
  Camera camera_;
  RendererOptions options_;
  std::vector<Eigen::Vector3f> bearings_;     ///< centre ray per pixel, row-major
  std::vector<Eigen::Vector3f> sub_bearings_; ///< n² rays per pixel when supersampling > 1
  std::vector<float> tile_bearings_;  ///< bearings_ tile by tile as x, y, z columns (the AVX2 path)
  std::size_t tile_stride_ = 0;      ///< entries per column and tile: tile_px², rounded up to 8
  float pixel_angle_rad_ = 0.0f;              ///< ≈ 1 / fx, for the texture footprint
  bool avx2_ = false;                         ///< options_.avx2 and the CPU has AVX2
  std::optional<PinholeFlow> pinhole_flow_;   ///< set when camera_ is a pinhole camera
  /// Per pixel, pinhole cameras only: 1 when the bearing b is in front of
  /// the camera with a margin (b_z > 2e-6 |b|, twice kMinCosAngle), so that
  /// PinholeFlow's front test passes for b and for every b · range, range > 0
  /// (flowRowAvx2 then needs no norm); 0: the pixel takes pixelFlow.
  std::vector<std::uint8_t> flow_in_front_;
  std::shared_ptr<ScratchPool> scratch_;      ///< tile buffers (their contents do not outlive a tile)
};

}  // namespace evio::simulator
