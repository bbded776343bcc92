// summary.yaml of an estimate folder (pipeline.h): what ran, how long each
// stage took and the backend's counters (each struct through its fields()).
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "evio/core/io/config.h"
#include "evio/core/version.h"
#include "evio/estimator/pipeline/pipeline.h"

namespace evio::estimator {

namespace {

void emitSeconds(YAML::Emitter& out, const char* key, double v) {
  out << YAML::Key << key << YAML::Value;
  config::emitDouble(out, v);
}

void emitVector(YAML::Emitter& out, const char* key, const Vec3& v) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 3; ++i) config::emitDouble(out, v(i));
  out << YAML::EndSeq;
}

/// The gyroscope bias from the first tracks, in °/s: the posterior and the
/// tracks' estimate alone, each with its per-axis σ.
void emitGyroBias(YAML::Emitter& out, const GyroBiasEstimate& e) {
  constexpr double kDeg = 180.0 / M_PI;
  out << YAML::Key << "gyro_bias_from_tracks" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "from_tracks" << YAML::Value << e.from_tracks;
  out << YAML::Key << "at_rest" << YAML::Value << e.at_rest;
  if (e.at_rest) {
    emitSeconds(out, "rest_s", e.rest_s);
    out << YAML::Key << "rest_prefix" << YAML::Value << e.rest_prefix;
  }
  if (e.rest_image_features > 0) {
    out << YAML::Key << "rest_image_features" << YAML::Value << e.rest_image_features;
    emitSeconds(out, "rest_image_chi2", e.rest_image_chi2);
  }
  emitVector(out, "b_g_degps", kDeg * e.b_g);
  emitVector(out, "sigma_degps", kDeg * e.covariance.diagonal().cwiseSqrt());
  emitVector(out, "filter_start_sigma_degps", kDeg * e.filter_start_covariance.diagonal().cwiseSqrt());
  if (e.at_rest) {
    emitVector(out, "b_a_mps2", e.rest_b_a);
    emitVector(out, "sigma_b_a_mps2", e.rest_b_a_covariance.diagonal().cwiseSqrt());
  }
  if (e.from_tracks) {
    emitVector(out, "tracks_b_g_degps", kDeg * e.data_b_g);
    emitVector(out, "tracks_sigma_degps", kDeg * e.data_covariance.diagonal().cwiseSqrt());
    out << YAML::Key << "pairs" << YAML::Value << e.pairs;
    out << YAML::Key << "residuals" << YAML::Value << e.residuals;
    out << YAML::Key << "outliers" << YAML::Value << e.outliers;
    emitSeconds(out, "bearing_sigma_rad", e.bearing_sigma_rad);
    emitSeconds(out, "split_half_q", e.split_half_q);
  }
  out << YAML::EndMap;
}

}  // namespace

std::string formatPipelineSummary(const PipelineResult& r, const PipelineOptions& options) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << evioVersion();
  out << YAML::Key << "method" << YAML::Value << options.method;
  out << YAML::Key << "initialization" << YAML::Value << options.init.mode;
  out << YAML::Key << "status" << YAML::Value << std::string(io::estimateStatusName(r.status.code));
  out << YAML::Key << "calibration" << YAML::Value << r.rig_source;
  out << YAML::Key << "tracker_camera" << YAML::Value << r.tracker_camera;
  out << YAML::Key << "events_file" << YAML::Value << r.events_file;
  emitSeconds(out, "data_start_s", nsToSeconds(r.t_first_ns));
  emitSeconds(out, "data_end_s", nsToSeconds(r.t_last_ns));
  if (r.initialization_t_ns) emitSeconds(out, "initialization_s", nsToSeconds(*r.initialization_t_ns));
  const double data_s = nsToSeconds(r.t_last_ns - r.initialization_t_ns.value_or(r.t_first_ns));
  emitSeconds(out, "data_after_initialization_s", data_s);
  config::Writer writer(out);
  out << YAML::Key << "counts" << YAML::Value;
  writer.write(r.counts);
  out << YAML::Key << "stage_times_s" << YAML::Value;
  writer.write(r.times);
  out << YAML::Key << "stage_cpu_s" << YAML::Value;
  writer.write(r.cpu);
  out << YAML::Key << "backend" << YAML::Value;
  writer.write(r.backend);
  if (r.eklt) {
    out << YAML::Key << "eklt" << YAML::Value;
    writer.write(*r.eklt);
  }
  if (r.track_lag) {  // the model lag = a + tau |v| the synchroniser compensated at the end
    out << YAML::Key << "track_lag" << YAML::Value << YAML::BeginMap;
    emitSeconds(out, "a_px", r.track_lag->a_px);
    emitSeconds(out, "tau_s", r.track_lag->tau_s);
    out << YAML::EndMap;
  }
  if (r.gyro_bias) emitGyroBias(out, *r.gyro_bias);
  out << YAML::Key << "notes" << YAML::Value << YAML::BeginSeq;
  for (const auto& n : r.notes) out << n;
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace evio::estimator
