// summary.yaml of an estimate folder (pipeline.h): what ran, how long each
// stage took and the backend's counters.
#include <yaml-cpp/yaml.h>

#include "evio/core/io/config.h"
#include "evio/estimator/pipeline/pipeline.h"

namespace evio::estimator {

namespace {

void emitSeconds(YAML::Emitter& out, const char* key, double v) {
  out << YAML::Key << key << YAML::Value;
  config::detail::emitDouble(out, v);
}

}  // namespace

std::string formatPipelineSummary(const PipelineResult& r, const PipelineOptions& options) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "method" << YAML::Value << options.method;
  out << YAML::Key << "status" << YAML::Value << std::string(io::estimateStatusName(r.status.code));
  out << YAML::Key << "calibration" << YAML::Value << r.rig_source;
  out << YAML::Key << "tracker_camera" << YAML::Value << r.tracker_camera;
  out << YAML::Key << "events_file" << YAML::Value << r.events_file;
  emitSeconds(out, "data_start_s", nsToSeconds(r.t_first_ns));
  emitSeconds(out, "data_end_s", nsToSeconds(r.t_last_ns));
  if (r.initialization_t_ns) emitSeconds(out, "initialization_s", nsToSeconds(*r.initialization_t_ns));
  const double data_s = nsToSeconds(r.t_last_ns - r.initialization_t_ns.value_or(r.t_first_ns));
  emitSeconds(out, "data_after_initialization_s", data_s);
  out << YAML::Key << "counts" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "events" << YAML::Value << r.events;
  out << YAML::Key << "events_kept" << YAML::Value << r.events_kept;
  out << YAML::Key << "frames" << YAML::Value << r.frames;
  out << YAML::Key << "imu_samples" << YAML::Value << r.imu_samples;
  out << YAML::Key << "track_points" << YAML::Value << r.track_points;
  out << YAML::Key << "measurement_sets" << YAML::Value << r.measurement_sets;
  out << YAML::Key << "poses" << YAML::Value << r.poses;
  out << YAML::EndMap;
  out << YAML::Key << "stage_times_s" << YAML::Value;
  config::detail::Writer writer(out);
  writer.write(r.times);
  const BackendStats& b = r.backend;
  out << YAML::Key << "backend" << YAML::Value << YAML::BeginMap;
  const auto count = [&](const char* key, std::int64_t v) { out << YAML::Key << key << YAML::Value << v; };
  count("imu_samples", b.imu_samples);
  count("imu_outliers_replaced", b.imu_outliers_replaced);
  count("imu_duplicates_dropped", b.imu_duplicates_dropped);
  count("imu_gaps", b.imu_gaps);
  count("measurement_sets", b.measurement_sets);
  count("measurements_late_dropped", b.measurements_late_dropped);
  count("measurements_before_init", b.measurements_before_init);
  count("features_undistort_failed", b.features_undistort_failed);
  count("msckf_features_used", b.msckf_features_used);
  count("msckf_features_rejected", b.msckf_features_rejected);
  count("msckf_features_no_parallax", b.msckf_features_no_parallax);
  count("msckf_triangulation_failed", b.msckf_triangulation_failed);
  count("slam_initialized_triangulated", b.slam_initialized_triangulated);
  count("slam_initialized_prior", b.slam_initialized_prior);
  count("slam_initialized_range", b.slam_initialized_range);
  count("slam_updates_rejected", b.slam_updates_rejected);
  count("slam_features_removed", b.slam_features_removed);
  count("slam_reanchored", b.slam_reanchored);
  count("range_updates", b.range_updates);
  count("range_rejected", b.range_rejected);
  out << YAML::EndMap;
  out << YAML::Key << "notes" << YAML::Value << YAML::BeginSeq;
  for (const auto& n : r.notes) out << n;
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace evio::estimator
