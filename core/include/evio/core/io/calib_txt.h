#pragma once
/// @file calib_txt.h
/// calib.txt of the Event-Camera Dataset (Mueggler et al. 2017): one line
///   fx fy cx cy k1 k2 p1 p2 k3
/// (pixels; OpenCV radial-tangential distortion, see camera/radtan_camera.h).
/// A line of 4 values (fx fy cx cy) is also read, as a pinhole camera. The
/// file holds no resolution: it comes from elsewhere (sensors.yaml, the images).
/// Blank lines and lines starting with '#' are ignored; any other extra line
/// is an error.

#include <string>
#include <string_view>

#include "evio/core/camera/camera.h"
#include "evio/core/eigen_types.h"

namespace evio::io {

/// The numbers of a calib.txt, exactly as in the file.
struct CalibTxt {
  Vec4 intrinsics = Vec4::Zero();  ///< fx, fy, cx, cy in pixels
  VecX distortion;                 ///< k1, k2, p1, p2, k3; empty for a 4-value file

  friend bool operator==(const CalibTxt& a, const CalibTxt& b) {
    return a.intrinsics == b.intrinsics && a.distortion.size() == b.distortion.size() &&
           a.distortion == b.distortion;
  }
};

/// Parses calib.txt text. Throws evio::Error "name:line: column k (fx): ..."
/// for a non-number, NaN or inf, a wrong number of values (not 4 or 9), or a
/// non-positive focal length; "name: ..." for an empty file.
CalibTxt parseCalibTxt(std::string_view text, const std::string& name = "<string>");

/// Reads a calib.txt file (throws evio::Error naming the file when missing).
CalibTxt readCalibTxt(const std::string& path);

/// One line with all values printed in the shortest form that reads back to
/// the same double (4 or 9 values, as in `calib`), ending in '\n'.
/// Throws evio::Error for non-finite values or a distortion length not 0 or 5.
std::string formatCalibTxt(const CalibTxt& calib);

/// Writes formatCalibTxt(calib) to `path` atomically.
void writeCalibTxt(const std::string& path, const CalibTxt& calib);

/// The calib.txt of a camera: radtan as is, pinhole with five zero
/// coefficients (the dataset always has 9 values). Throws evio::Error for
/// models calib.txt cannot express (equidistant).
CalibTxt calibTxtFromCamera(const Camera& camera);

/// The camera of a calib.txt with the given resolution: pinhole when the file
/// has 4 values or all five coefficients are exactly zero (the same mapping),
/// radtan otherwise. Validates like Camera::create.
Camera cameraFromCalibTxt(const CalibTxt& calib, int width, int height);

}  // namespace evio::io
