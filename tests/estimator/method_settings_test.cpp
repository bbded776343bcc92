// A method's own section of an estimator configuration (method_settings.h):
// merged over the shared settings for that method only, below --set, and
// removed for every method, with messages naming the section's line.
#include <gtest/gtest.h>

#include <string>

#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/estimator/pipeline/method_settings.h"
#include "evio/estimator/pipeline/pipeline_options.h"

namespace evio::estimator {
namespace {

const char* kShared =
    "backend:\n"                       // line 1
    "  msckf_iterations: 3\n"          // 2
    "  max_slam_features: 15\n"        // 3
    "frontend:\n"                      // 4
    "  klt:\n"                         // 5
    "    position_sigma_px: 2.5\n"     // 6
    "klt-vio:\n"                       // 7
    "  backend:\n"                     // 8
    "    msckf_rotation_rows: true\n"  // 9
    "    max_slam_features: 10\n"      // 10
    "eklt-vio:\n"                      // 11
    "  backend:\n"                     // 12
    "    max_slam_features: 20\n";     // 13

PipelineOptions optionsFor(const std::string& method, config::Document doc) {
  config::applyOverride(doc, "method=" + method);
  applyMethodSettings(doc, method);
  PipelineOptions o = PipelineOptions::forMethod(method);
  config::fill(doc, "", o);
  return o;
}

TEST(MethodSettings, EachMethodTakesItsOwnSectionOverTheSharedSettings) {
  const PipelineOptions klt = optionsFor("klt-vio", config::loadString(kShared, "sim.yaml"));
  EXPECT_TRUE(klt.backend.msckf_rotation_rows);
  EXPECT_EQ(klt.backend.max_slam_features, 10);
  EXPECT_EQ(klt.backend.msckf_iterations, 3);          // a shared sibling kept
  EXPECT_DOUBLE_EQ(klt.frontend.klt.position_sigma_px, 2.5);
  const PipelineOptions eklt = optionsFor("eklt-vio", config::loadString(kShared, "sim.yaml"));
  EXPECT_FALSE(eklt.backend.msckf_rotation_rows);      // KLT-VIO's section is not EKLT-VIO's
  EXPECT_EQ(eklt.backend.max_slam_features, 20);
  const PipelineOptions haste = optionsFor("haste-vio", config::loadString(kShared, "sim.yaml"));
  EXPECT_FALSE(haste.backend.msckf_rotation_rows);
  EXPECT_EQ(haste.backend.max_slam_features, 15);      // no section: the shared settings alone
}

TEST(MethodSettings, EverySectionIsRemoved) {
  config::Document doc = config::loadString(kShared, "sim.yaml");
  applyMethodSettings(doc, "haste-vio");
  EXPECT_FALSE(doc.root["klt-vio"].IsDefined());
  EXPECT_FALSE(doc.root["eklt-vio"].IsDefined());
}

TEST(MethodSettings, TheCommandLineWinsOverTheSection) {
  config::Document doc = config::loadString(kShared, "sim.yaml");
  config::applyOverride(doc, "backend.max_slam_features=7");
  config::applyOverride(doc, "backend.msckf_rotation_rows=false");
  const PipelineOptions klt = optionsFor("klt-vio", doc);
  EXPECT_EQ(klt.backend.max_slam_features, 7);
  EXPECT_FALSE(klt.backend.msckf_rotation_rows);
}

TEST(MethodSettings, ASectionThatIsNotAMapIsOneErrorNamingItsLine) {
  config::Document doc = config::loadString("backend:\n  msckf_iterations: 3\nklt-vio: true\n", "sim.yaml");
  try {
    applyMethodSettings(doc, "eklt-vio");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sim.yaml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("klt-vio"), std::string::npos) << e.what();
  }
}

TEST(MethodSettings, AWrongValueInTheSectionIsReportedAtItsLine) {
  const std::string text = std::string(kShared) + "haste-vio:\n  backend:\n    max_slam_features: many\n";  // line 16
  try {
    (void)optionsFor("haste-vio", config::loadString(text, "sim.yaml"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sim.yaml:16"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace evio::estimator
