#include "message_conversion.h"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>

#include "evio/core/error.h"

namespace evio::bags::detail {

TimeNs nsFromRosTime(const ros::Time& t) {
  if (t.nsec >= 1'000'000'000u)
    throw Error("time " + std::to_string(t.sec) + " s + " + std::to_string(t.nsec) + " ns: nsec is not below 10^9");
  return static_cast<TimeNs>(t.sec) * kNsPerSecond + static_cast<TimeNs>(t.nsec);
}

ros::Time rosTimeFromNs(TimeNs t_ns) {
  if (t_ns < 0) throw Error("time " + secondsText(t_ns, 9) + ": ROS 1 time cannot be negative");
  const TimeNs sec = t_ns / kNsPerSecond;
  if (sec > static_cast<TimeNs>(std::numeric_limits<std::uint32_t>::max()))
    throw Error("time " + secondsText(t_ns, 9) + ": beyond what ROS 1 time holds (2^32 s)");
  return ros::Time(static_cast<std::uint32_t>(sec), static_cast<std::uint32_t>(t_ns % kNsPerSecond));
}

void appendEvents(const RosEventArray& msg, EventArray& out, TimeNs& last_t_ns) {
  out.reserve(out.size() + msg.events.size());
  for (std::size_t i = 0; i < msg.events.size(); ++i) {
    const RosEvent& e = msg.events[i];
    const TimeNs t_ns = nsFromRosTime(e.ts);
    if (t_ns < last_t_ns)
      throw Error("event " + std::to_string(i) + ": time " + secondsText(t_ns, 9) + " before the previous event's " +
                  secondsText(last_t_ns, 9) + " (events not sorted)");
    if ((msg.width > 0 && e.x >= msg.width) || (msg.height > 0 && e.y >= msg.height))
      throw Error("event " + std::to_string(i) + ": pixel (" + std::to_string(e.x) + ", " + std::to_string(e.y) +
                  ") outside the " + std::to_string(msg.width) + " x " + std::to_string(msg.height) + " sensor");
    if (e.polarity > 1) throw Error("event " + std::to_string(i) + ": polarity byte " + std::to_string(e.polarity) + " is not 0 or 1");
    out.push_back(t_ns, e.x, e.y, e.polarity != 0);
    last_t_ns = t_ns;
  }
}

namespace {

/// Channels and the OpenCV conversion to grey of an 8-bit encoding; 0 if unknown.
int channelsOf(const std::string& encoding, int& to_grey) {
  to_grey = -1;
  if (encoding == "mono8" || encoding == "8UC1") return 1;
  if (encoding == "bgr8") return to_grey = cv::COLOR_BGR2GRAY, 3;
  if (encoding == "rgb8") return to_grey = cv::COLOR_RGB2GRAY, 3;
  if (encoding == "bgra8") return to_grey = cv::COLOR_BGRA2GRAY, 4;
  if (encoding == "rgba8") return to_grey = cv::COLOR_RGBA2GRAY, 4;
  return 0;
}

}  // namespace

cv::Mat greyFromImage(const RosImage& msg) {
  int to_grey = -1;
  const int channels = channelsOf(msg.encoding, to_grey);
  if (channels == 0)
    throw Error("image encoding '" + msg.encoding + "' is not read (mono8, 8UC1, rgb8, bgr8, rgba8, bgra8)");
  if (msg.width == 0 || msg.height == 0 || msg.width > 1u << 16 || msg.height > 1u << 16)
    throw Error("image size " + std::to_string(msg.width) + " x " + std::to_string(msg.height) + " is empty or above 65536");
  const std::uint64_t row = std::uint64_t{msg.width} * static_cast<std::uint64_t>(channels);
  if (msg.step < row) throw Error("image step " + std::to_string(msg.step) + " is shorter than a row of " + std::to_string(row) + " bytes");
  if (msg.data.size() < std::uint64_t{msg.step} * msg.height)
    throw Error("image data of " + std::to_string(msg.data.size()) + " bytes is shorter than height x step = " +
                std::to_string(std::uint64_t{msg.step} * msg.height));
  const cv::Mat view(static_cast<int>(msg.height), static_cast<int>(msg.width), CV_8UC(channels),
                     const_cast<std::uint8_t*>(msg.data.data()), msg.step);
  cv::Mat grey;
  if (to_grey < 0) grey = view.clone();
  else cv::cvtColor(view, grey, to_grey);
  return grey;
}

RosImage imageFromGrey(const cv::Mat& grey, TimeNs t_ns, const std::string& frame_id) {
  require(grey.type() == CV_8UC1, "frame is not 8-bit grey");
  RosImage msg;
  msg.header.stamp = rosTimeFromNs(t_ns);
  msg.header.frame_id = frame_id;
  msg.height = static_cast<std::uint32_t>(grey.rows);
  msg.width = static_cast<std::uint32_t>(grey.cols);
  msg.encoding = "mono8";
  msg.is_bigendian = 0;
  msg.step = msg.width;
  msg.data.resize(std::size_t{msg.step} * msg.height);
  for (int r = 0; r < grey.rows; ++r)
    std::copy(grey.ptr<std::uint8_t>(r), grey.ptr<std::uint8_t>(r) + grey.cols, msg.data.begin() + std::ptrdiff_t{r} * grey.cols);
  return msg;
}

namespace {

void requireFinite(const Vec3& v, const char* field) {
  if (!v.allFinite()) throw Error(std::string(field) + ": not finite");
}

}  // namespace

ImuSample imuFromRos(const RosImu& msg) {
  ImuSample s;
  s.t_ns = nsFromRosTime(msg.header.stamp);
  s.acc_B = Vec3(msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z);
  s.gyro_B = Vec3(msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z);
  requireFinite(s.acc_B, "linear_acceleration");
  requireFinite(s.gyro_B, "angular_velocity");
  return s;
}

RosImu rosFromImu(const ImuSample& sample, const std::string& frame_id) {
  RosImu msg;
  msg.header.stamp = rosTimeFromNs(sample.t_ns);
  msg.header.frame_id = frame_id;
  msg.orientation.w = 1.0;
  msg.orientation_covariance[0] = -1.0;  // REP 145: no orientation estimate
  msg.linear_acceleration.x = sample.acc_B.x();
  msg.linear_acceleration.y = sample.acc_B.y();
  msg.linear_acceleration.z = sample.acc_B.z();
  msg.angular_velocity.x = sample.gyro_B.x();
  msg.angular_velocity.y = sample.gyro_B.y();
  msg.angular_velocity.z = sample.gyro_B.z();
  return msg;
}

StampedPose poseFromRos(const RosPoseStamped& msg) {
  const auto& p = msg.pose.position;
  const auto& o = msg.pose.orientation;
  const Vec3 position(p.x, p.y, p.z);
  const Quat q(o.w, o.x, o.y, o.z);
  requireFinite(position, "pose.position");
  if (!q.coeffs().allFinite()) throw Error("pose.orientation: not finite");
  const double norm = q.norm();
  if (!(std::fabs(norm - 1.0) <= 0.01))
    throw Error("pose.orientation: quaternion norm " + std::to_string(norm) + " is not 1 (within 1 %)");
  return StampedPose{nsFromRosTime(msg.header.stamp), Pose(q, position)};
}

RosPoseStamped rosFromPose(const StampedPose& pose, const std::string& frame_id) {
  RosPoseStamped msg;
  msg.header.stamp = rosTimeFromNs(pose.t_ns);
  msg.header.frame_id = frame_id;
  const Vec3& p = pose.pose.translation();
  const Quat& q = pose.pose.quaternion();
  msg.pose.position.x = p.x();
  msg.pose.position.y = p.y();
  msg.pose.position.z = p.z();
  msg.pose.orientation.x = q.x();
  msg.pose.orientation.y = q.y();
  msg.pose.orientation.z = q.z();
  msg.pose.orientation.w = q.w();
  return msg;
}

io::CalibTxt calibFromCameraInfo(const RosCameraInfo& msg) {
  const auto& K = msg.K;  // row-major 3x3
  if (K[1] != 0.0 || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0)
    throw Error("K = [fx 0 cx; 0 fy cy; 0 0 1] expected (no skew), got K[1] K[3] K[6..8] = " + std::to_string(K[1]) +
                " " + std::to_string(K[3]) + " " + std::to_string(K[6]) + " " + std::to_string(K[7]) + " " +
                std::to_string(K[8]));
  const bool plumb_bob = msg.distortion_model == "plumb_bob" || msg.distortion_model == "radtan";
  if (!(plumb_bob && (msg.D.size() == 5 || msg.D.empty())) && !(msg.distortion_model.empty() && msg.D.empty()))
    throw Error("distortion_model '" + msg.distortion_model + "' with " + std::to_string(msg.D.size()) +
                " coefficients: calib.txt holds plumb_bob (5 coefficients) or none");
  io::CalibTxt calib;
  calib.intrinsics = Vec4(K[0], K[4], K[2], K[5]);
  calib.distortion = VecX(static_cast<Eigen::Index>(msg.D.size()));
  for (std::size_t i = 0; i < msg.D.size(); ++i) calib.distortion[static_cast<Eigen::Index>(i)] = msg.D[i];
  // Validates as calib.txt does (finite, positive focal lengths).
  return io::parseCalibTxt(io::formatCalibTxt(calib), "camera_info");
}

RosCameraInfo cameraInfoFromCalib(const io::CalibTxt& calib, int width, int height, TimeNs t_ns,
                                  const std::string& frame_id) {
  RosCameraInfo msg;
  msg.header.stamp = rosTimeFromNs(t_ns);
  msg.header.frame_id = frame_id;
  msg.width = static_cast<std::uint32_t>(width);
  msg.height = static_cast<std::uint32_t>(height);
  msg.distortion_model = "plumb_bob";
  for (Eigen::Index i = 0; i < calib.distortion.size(); ++i) msg.D.push_back(calib.distortion[i]);
  const double fx = calib.intrinsics[0], fy = calib.intrinsics[1], cx = calib.intrinsics[2], cy = calib.intrinsics[3];
  msg.K = {fx, 0, cx, 0, fy, cy, 0, 0, 1};
  msg.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  msg.P = {fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0};
  return msg;
}

}  // namespace evio::bags::detail
