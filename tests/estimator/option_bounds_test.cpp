// Every rate and size option of the estimator has an upper bound (issue 19):
// an absurd value is one evio::Error naming the field (section.key), and the
// largest allowed value still validates, so the bound is where it says.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/estimator/pipeline/pipeline_options.h"

namespace evio::estimator {
namespace {

struct Bound {
  std::string key;      ///< dotted option path, as --set takes it
  std::string largest;  ///< the largest value that validates
  std::string absurd;   ///< a value far beyond it
  std::vector<std::string> with = {};  ///< options the key needs ("key=value")
};

/// b.with plus key=value.
std::vector<std::string> overridesOf(const Bound& b, const std::string& value) {
  std::vector<std::string> o = b.with;
  o.push_back(b.key + "=" + value);
  return o;
}

/// The options of `method` with `overrides` ("key=value") applied as `--set` does; validated.
PipelineOptions optionsWith(const std::string& method, const std::vector<std::string>& overrides) {
  config::Document doc = config::loadString(config::toYaml(PipelineOptions::forMethod(method)));
  for (const std::string& o : overrides) config::applyOverride(doc, o);
  PipelineOptions o;
  config::fill(doc, "", o);
  o.validate();
  return o;
}

const std::vector<Bound>& bounds() {
  static const std::vector<Bound> b = {
      {"backend.window_size", "200", "100000"},
      {"backend.max_slam_features", "1000", "1000000"},
      {"backend.triangulation_max_iterations", "1000", "1000000000"},
      {"backend.iekf_iterations", "100", "1000000"},
      {"backend.msckf_iterations", "100", "1000000"},
      {"backend.slam_prior_track_iterations", "50", "1000000",
       {"backend.slam_prior_init_with_track=true", "backend.slam_prior_track_update=true"}},
      {"backend.max_delay_s", "60", "1e9"},
      {"backend.slam_update_interval_s", "60", "1e9"},
      {"backend.slam_update_min_displacement_normalized", "1", "2"},
      {"frontend.eklt.error_time_s", "60", "1e9"},
      {"frontend.klt.error_time_s", "60", "1e9"},
      {"frontend.haste.error_time_s", "60", "1e9"},
      {"frontend.klt.position_sigma_px", "100", "1e9"},
      {"frontend.klt.backward_check_px", "1000", "1e9"},
      {"frontend.haste.position_sigma_px", "100", "1e9"},
      {"frontend.eklt.position_sigma_cost_ref", "2", "1e9"},  // the cost lies in [0, 2]
      {"backend.static_window_s", "3600", "1e12"},
      {"frontend.eklt.max_features", "10000", "100000000"},
      {"frontend.eklt.harris_block_size", "101", "1000000"},
      {"frontend.eklt.batch_max_events", "1000000", "2000000000"},
      {"frontend.eklt.max_iterations", "1000", "1000000000"},
      {"frontend.eklt.bootstrap_window_px", "255", "100000"},
      {"frontend.eklt.bootstrap_pyramid_levels", "16", "1000"},
      {"frontend.haste.harris_block_size", "101", "1000000"},
      {"frontend.klt.max_features", "10000", "100000000"},
      {"frontend.klt.window_px", "255", "100000"},
      {"frontend.klt.pyramid_levels", "16", "1000"},
      {"frontend.klt.max_iterations", "1000", "1000000000"},
      {"frontend.klt.border_px", "65536", "1000000000"},
      {"frontend.reconstruction.output_rate_hz", "1e5", "1e12"},
      {"sync.rate_hz", "1e5", "1e12"},
      {"sync.min_rate_hz", "1e5", "1e12"},
      {"tracks.rate_hz", "1e5", "1e12"},
      {"calibration.imu_rate_hz", "1e5", "1e12"},
      {"health.window_s", "3600", "1e12"},
      {"health.min_window_dof", "1000000", "2000000000"},
  };
  return b;
}

TEST(OptionBounds, AbsurdValueIsOneErrorNamingTheField) {
  for (const Bound& b : bounds()) {
    try {
      optionsWith("eklt-vio", overridesOf(b, b.absurd));
      ADD_FAILURE() << b.key << "=" << b.absurd << " was accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(b.key), std::string::npos) << b.key << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    }
  }
}

TEST(OptionBounds, LargestAllowedValueValidates) {
  for (const Bound& b : bounds()) EXPECT_NO_THROW(optionsWith("eklt-vio", overridesOf(b, b.largest))) << b.key;
}

TEST(OptionBounds, CalibrationSensorSizeBounded) {
  EXPECT_NO_THROW(optionsWith("klt-vio", {"calibration.width=65536", "calibration.height=65536"}));
  try {
    optionsWith("klt-vio", {"calibration.width=100000", "calibration.height=100000"});
    ADD_FAILURE() << "a 100000 px sensor was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("calibration.width"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace evio::estimator
