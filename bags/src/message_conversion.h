#pragma once
/// @file message_conversion.h
/// ROS 1 messages ↔ evio's types. Times: ros::Time (uint32 s, uint32 ns
/// since the epoch of the recording) ↔ TimeNs (int64 ns), exact both ways.
/// Units are the same on both sides (ROS REP 103: SI, m/s², rad/s); frames:
/// Imu in the IMU frame B, PoseStamped the event camera E in the world W
/// (T_W_E, as groundtruth.txt), EventArray pixels with (0, 0) top left.
/// Failures throw evio::Error saying what is wrong; the caller adds the
/// bag, topic and message.

#include <opencv2/core/mat.hpp>
#include <ros/time.h>

#include "evio/bags/ros/dvs_msgs.h"
#include "evio/bags/ros/ros_messages.h"
#include "evio/core/event.h"
#include "evio/core/imu_sample.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/pose.h"

namespace evio::bags::detail {

using RosEventArray = dvs_msgs::EventArray_<RosAllocator<void>>;
using RosEvent = dvs_msgs::Event_<RosAllocator<void>>;

/// sec · 10⁹ + nsec. Throws when nsec ≥ 10⁹ (not a normalised ROS time).
TimeNs nsFromRosTime(const ros::Time& t);
/// Throws for t < 0 or t ≥ 2³² s, which ros::Time cannot hold.
ros::Time rosTimeFromNs(TimeNs t_ns);

/// Appends the message's events to `out`. Throws when an event is outside
/// width × height (when the message gives them) or earlier than the one
/// before it (`last_t_ns`, updated).
void appendEvents(const RosEventArray& msg, EventArray& out, TimeNs& last_t_ns);

/// 8-bit grey frame of an Image: mono8 / 8UC1 as is, rgb8 / bgr8 / rgba8 /
/// bgra8 converted to grey (OpenCV's weights). Throws for other encodings,
/// a step shorter than a row, or data shorter than height · step.
cv::Mat greyFromImage(const RosImage& msg);
/// A mono8 Image of a CV_8UC1 frame.
RosImage imageFromGrey(const cv::Mat& grey, TimeNs t_ns, const std::string& frame_id);

ImuSample imuFromRos(const RosImu& msg);
/// An Imu message with the orientation marked unknown (covariance[0] = -1,
/// ROS's convention) and the other covariances 0 (= unknown).
RosImu rosFromImu(const ImuSample& sample, const std::string& frame_id);

/// Throws when the quaternion's norm is not 1 within 1 % (as the TUM reader).
StampedPose poseFromRos(const RosPoseStamped& msg);
RosPoseStamped rosFromPose(const StampedPose& pose, const std::string& frame_id);

/// calib.txt numbers of a CameraInfo with distortion model plumb_bob (or an
/// empty D, read as a pinhole): K = [fx 0 cx; 0 fy cy; 0 0 1] (skew must be
/// 0), D = k1 k2 p1 p2 k3 (ROS and OpenCV use the same order). Throws for
/// other models, other D lengths or a K that is not of that form.
io::CalibTxt calibFromCameraInfo(const RosCameraInfo& msg);
/// The CameraInfo of a calib.txt at a resolution: plumb_bob, K as above,
/// R = identity, P = [K | 0].
RosCameraInfo cameraInfoFromCalib(const io::CalibTxt& calib, int width, int height, TimeNs t_ns,
                                  const std::string& frame_id);

}  // namespace evio::bags::detail
