#include "evio/core/io/calib_txt.h"

#include <gtest/gtest.h>

#include <string>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "temp_dir.h"

namespace evio {
namespace {

// calib.txt of the Event-Camera Dataset's DAVIS240C sequences (e.g. shapes_6dof).
const char* kDavis240c =
    "199.092366542 198.82882047 132.192071378 110.712660011 -0.368436311798 0.150947243557 "
    "-0.000296130534385 -0.000759431726241 0.0\n";

TEST(CalibTxt, ReadsTheDatasetLine) {
  const io::CalibTxt c = io::parseCalibTxt(kDavis240c, "calib.txt");
  EXPECT_EQ(c.intrinsics, Vec4(199.092366542, 198.82882047, 132.192071378, 110.712660011));
  ASSERT_EQ(c.distortion.size(), 5);
  EXPECT_EQ(c.distortion[0], -0.368436311798);
  EXPECT_EQ(c.distortion[3], -0.000759431726241);
  EXPECT_EQ(c.distortion[4], 0.0);
  const Camera cam = io::cameraFromCalibTxt(c, 240, 180);
  EXPECT_EQ(cam.model(), "radtan");
  EXPECT_EQ(cam.params().head<4>(), c.intrinsics);
  EXPECT_EQ(cam.distortion(), c.distortion);
}

TEST(CalibTxt, AcceptsFourValuesTabsCrlfAndComments) {
  const io::CalibTxt c = io::parseCalibTxt("# pinhole\r\n\r\n  200\t201 120.5  90\r\n\n", "c.txt");
  EXPECT_EQ(c.intrinsics, Vec4(200, 201, 120.5, 90));
  EXPECT_EQ(c.distortion.size(), 0);
  EXPECT_EQ(io::cameraFromCalibTxt(c, 240, 180).model(), "pinhole");
  // No trailing newline is fine too.
  EXPECT_EQ(io::parseCalibTxt("200 201 120.5 90", "c.txt"), c);
}

TEST(CalibTxt, RoundTripThroughFileIsExact) {
  test::TempDir dir;
  const std::string path = dir.file("calib.txt");
  io::CalibTxt c;
  c.intrinsics = Vec4(199.092366542, 0.1 + 0.2, 132.192071378, 1e-300);
  c.distortion.resize(5);
  c.distortion << -0.368436311798, 1.0 / 3.0, -2.5e-17, 5e-324, -0.0;
  io::writeCalibTxt(path, c);
  const io::CalibTxt back = io::readCalibTxt(path);
  EXPECT_EQ(back, c);
  EXPECT_TRUE(std::signbit(back.distortion[4]));
  // Four values stay four values.
  io::CalibTxt pinhole;
  pinhole.intrinsics = Vec4(320, 320, 172.5, 129.5);
  EXPECT_EQ(io::formatCalibTxt(pinhole), "320 320 172.5 129.5\n");
  EXPECT_EQ(io::parseCalibTxt(io::formatCalibTxt(pinhole), "p.txt"), pinhole);
  // The dataset's own line reads back to the same numbers after rewriting.
  const io::CalibTxt davis = io::parseCalibTxt(kDavis240c, "calib.txt");
  EXPECT_EQ(io::parseCalibTxt(io::formatCalibTxt(davis), "again.txt"), davis);
}

TEST(CalibTxt, CameraRoundTrip) {
  RadTanCamera::Params p;
  p << 199.1, 198.8, 132.2, 110.7, -0.37, 0.15, -3e-4, -7.6e-4, 0.01;
  const Camera radtan = RadTanCamera(240, 180, p);
  EXPECT_EQ(io::cameraFromCalibTxt(io::calibTxtFromCamera(radtan), 240, 180), radtan);

  const Camera pinhole = PinholeCamera(346, 260, PinholeCamera::Params(320, 321, 173, 130));
  const io::CalibTxt c = io::calibTxtFromCamera(pinhole);
  EXPECT_EQ(c.distortion, VecX::Zero(5));  // the dataset always has 9 values
  EXPECT_EQ(io::formatCalibTxt(c), "320 321 173 130 0 0 0 0 0\n");
  EXPECT_EQ(io::cameraFromCalibTxt(c, 346, 260), pinhole);

  EquidistantCamera::Params e;
  e << 300, 300, 320, 240, 0.01, 0, 0, 0;
  EXPECT_THROW(io::calibTxtFromCamera(EquidistantCamera(640, 480, e)), Error);
}

/// Expects parseCalibTxt(text) to throw an evio::Error containing every
/// string of `expected`.
void expectBad(const std::string& text, std::initializer_list<std::string> expected) {
  try {
    io::parseCalibTxt(text, "calib.txt");
    ADD_FAILURE() << "expected an error for '" << text << "'";
  } catch (const Error& e) {
    for (const auto& s : expected)
      EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what() << "\n(wanted " << s << ")";
  }
}

TEST(CalibTxt, BadInputNamesLineAndColumn) {
  expectBad("200 200 120 90 0.1 0.2 0 0\n", {"calib.txt:1", "got 8"});
  expectBad("200 200 120\n", {"calib.txt:1", "got 3"});
  expectBad("\n200 200 120 90 0.1 0.2 0 0 0 7\n", {"calib.txt:2", "got 10"});
  expectBad("200 200 abc 90 0 0 0 0 0\n", {"calib.txt:1", "column 3 (cx)", "'abc'"});
  expectBad("200 200 120 90 0 0 0.1x 0 0\n", {"calib.txt:1", "column 7 (p1)", "'0.1x'"});
  expectBad("200 200 120 90 nan 0 0 0 0\n", {"calib.txt:1", "column 5 (k1)", "finite"});
  expectBad("200 inf 120 90 0 0 0 0 0\n", {"calib.txt:1", "column 2 (fy)", "finite"});
  expectBad("200 200 120 90 0 0 0 0 -infinity\n", {"calib.txt:1", "column 9 (k3)", "finite"});
  expectBad("200 200 120 90 0 1e999 0 0 0\n", {"calib.txt:1", "column 6 (k2)", "range"});
  expectBad("0 200 120 90 0 0 0 0 0\n", {"calib.txt:1", "column 1 (fx)", "> 0"});
  expectBad("200 -1 120 90 0 0 0 0 0\n", {"calib.txt:1", "column 2 (fy)", "> 0"});
  expectBad("200 200 120 90\n200 200 120 90\n", {"calib.txt:2", "extra line"});
  expectBad("", {"calib.txt", "no calibration line"});
  expectBad("# only a comment\n\n", {"calib.txt", "no calibration line"});
}

TEST(CalibTxt, MissingFileAndUnwritableValues) {
  try {
    io::readCalibTxt("/nonexistent/calib.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/calib.txt"), std::string::npos);
  }
  io::CalibTxt c;
  c.intrinsics = Vec4(200, 200, std::numeric_limits<double>::quiet_NaN(), 90);
  EXPECT_THROW(io::formatCalibTxt(c), Error);
  c.intrinsics = Vec4(200, 200, 120, 90);
  c.distortion = VecX::Zero(4);
  EXPECT_THROW(io::formatCalibTxt(c), Error);
  // A valid calib.txt whose camera is invalid for the resolution given.
  EXPECT_THROW(io::cameraFromCalibTxt(io::parseCalibTxt(kDavis240c), 0, 180), Error);
}

}  // namespace
}  // namespace evio
