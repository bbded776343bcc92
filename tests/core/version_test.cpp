#include "evio/core/version.h"

#include <gtest/gtest.h>

namespace evio {
namespace {

TEST(Version, IsEvioAndTheProjectVersion) {
  // The number comes from project(evio VERSION …) in the top-level CMakeLists.txt.
  EXPECT_STREQ(evioVersion(), "evio 0.1.0");
}

}  // namespace
}  // namespace evio
