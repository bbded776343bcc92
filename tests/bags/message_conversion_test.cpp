// ROS messages ↔ evio types: exact times, the checks that name bad input.
#include "message_conversion.h"

#include <gtest/gtest.h>

#include "evio/bags/bag_topics.h"
#include "evio/core/error.h"

namespace evio::bags::detail {
namespace {

TEST(RosTime, ExactBothWaysAndBounded) {
  const TimeNs t = 1468939993'067416301;
  const ros::Time r = rosTimeFromNs(t);
  EXPECT_EQ(r.sec, 1468939993u);
  EXPECT_EQ(r.nsec, 67416301u);
  EXPECT_EQ(nsFromRosTime(r), t);
  EXPECT_EQ(nsFromRosTime(rosTimeFromNs(0)), 0);
  EXPECT_EQ(nsFromRosTime(rosTimeFromNs(4294967295'999999999)), 4294967295'999999999);
  EXPECT_THROW(rosTimeFromNs(-1), Error);
  EXPECT_THROW(rosTimeFromNs(4294967296'000000000), Error);
  ros::Time bad;
  bad.sec = 1;
  bad.nsec = 1'000'000'000u;
  EXPECT_THROW(nsFromRosTime(bad), Error);
}

RosEventArray events(std::initializer_list<std::tuple<int, int, TimeNs, int>> list, std::uint32_t w, std::uint32_t h) {
  RosEventArray msg;
  msg.width = w;
  msg.height = h;
  for (const auto& [x, y, t, p] : list) {
    RosEvent e;
    e.x = static_cast<std::uint16_t>(x), e.y = static_cast<std::uint16_t>(y), e.ts = rosTimeFromNs(t);
    e.polarity = static_cast<std::uint8_t>(p);
    msg.events.push_back(e);
  }
  return msg;
}

TEST(Events, AppendsAndChecksOrderPixelsPolarity) {
  EventArray out;
  TimeNs last = 0;
  appendEvents(events({{1, 2, 10, 1}, {239, 179, 10, 0}}, 240, 180), out, last);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1], (Event{10, 239, 179, false}));
  EXPECT_EQ(last, 10);
  EXPECT_THROW(appendEvents(events({{1, 2, 9, 1}}, 240, 180), out, last), Error);  // earlier than 10
  EXPECT_THROW(appendEvents(events({{240, 2, 11, 1}}, 240, 180), out, last), Error);
  EXPECT_THROW(appendEvents(events({{2, 180, 11, 1}}, 240, 180), out, last), Error);
  EXPECT_THROW(appendEvents(events({{2, 2, 11, 2}}, 240, 180), out, last), Error);
  appendEvents(events({{4000, 3000, 11, 1}}, 0, 0), out, last);  // size not given: not checked
  EXPECT_EQ(out.size(), 3u);
}

TEST(Images, GreyFromEncodingsAndBadSizes) {
  RosImage msg;
  msg.width = 3, msg.height = 2, msg.encoding = "mono8", msg.step = 4;  // a padded row
  msg.data = {1, 2, 3, 99, 4, 5, 6, 99};
  cv::Mat grey = greyFromImage(msg);
  ASSERT_EQ(grey.size(), cv::Size(3, 2));
  EXPECT_EQ(grey.at<std::uint8_t>(1, 2), 6);
  msg.encoding = "rgb8", msg.step = 9;
  msg.data.assign(18, 77);
  EXPECT_EQ(greyFromImage(msg).at<std::uint8_t>(1, 1), 77);
  msg.data.resize(17);
  EXPECT_THROW(greyFromImage(msg), Error);
  msg.encoding = "mono16";
  EXPECT_THROW(greyFromImage(msg), Error);
  msg.encoding = "mono8", msg.step = 2;
  EXPECT_THROW(greyFromImage(msg), Error);

  const RosImage back = imageFromGrey(grey, 5, "cam");
  EXPECT_EQ(back.encoding, "mono8");
  EXPECT_EQ(back.step, 3u);
  EXPECT_EQ(std::vector<std::uint8_t>(back.data.begin(), back.data.end()), (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
}

TEST(Imu, NoOrientationAndExactValues) {
  const ImuSample s{123, Vec3(0.1, -9.81, 3.7e-9), Vec3(1e-300, -2.5, 0.3)};
  const RosImu msg = rosFromImu(s, "imu");
  EXPECT_EQ(msg.orientation_covariance[0], -1.0);  // REP 145: orientation unknown
  EXPECT_EQ(imuFromRos(msg), s);
  RosImu bad = msg;
  bad.angular_velocity.y = std::nan("");
  EXPECT_THROW(imuFromRos(bad), Error);
}

TEST(Poses, QuaternionNormChecked) {
  const StampedPose p{42, Pose(Quat(0.5, 0.5, -0.5, 0.5), Vec3(1, -2, 3.25))};
  RosPoseStamped msg = rosFromPose(p, "world");
  const StampedPose back = poseFromRos(msg);
  EXPECT_EQ(back.t_ns, 42);
  EXPECT_EQ(back.pose.translation(), p.pose.translation());
  EXPECT_EQ(back.pose.quaternion().coeffs(), p.pose.quaternion().coeffs());
  msg.pose.orientation.w = 0.6;  // norm 1.05
  EXPECT_THROW(poseFromRos(msg), Error);
}

TEST(CameraInfo, PlumbBobBothWays) {
  io::CalibTxt calib;
  calib.intrinsics = Vec4(199.092366542, 198.82882047, 132.192071378, 110.712660011);
  calib.distortion = VecX(5);
  calib.distortion << -0.368436311798, 0.150947243557, -0.000296130534385, -0.000759431726241, 0.0;
  RosCameraInfo msg = cameraInfoFromCalib(calib, 240, 180, 0, "dvs");
  EXPECT_EQ(msg.distortion_model, "plumb_bob");
  EXPECT_EQ(msg.K[2], 132.192071378);
  EXPECT_EQ(msg.P[6], 110.712660011);
  EXPECT_EQ(calibFromCameraInfo(msg), calib);
  msg.D.resize(4);
  EXPECT_THROW(calibFromCameraInfo(msg), Error);
  msg.D.clear();
  EXPECT_EQ(calibFromCameraInfo(msg).distortion.size(), 0);
  msg.K[1] = 0.5;  // skew
  EXPECT_THROW(calibFromCameraInfo(msg), Error);
  msg.K[1] = 0;
  msg.distortion_model = "equidistant";
  msg.D.assign(4, 0.01);
  EXPECT_THROW(calibFromCameraInfo(msg), Error);
}

TEST(TopicOverrides, ParsedAndChecked) {
  const auto o = parseTopicOverrides({"events=/cam0/events", "frames="});
  EXPECT_EQ(o.at(TopicKind::kEvents), "/cam0/events");
  EXPECT_EQ(o.at(TopicKind::kFrames), "");
  EXPECT_THROW(parseTopicOverrides({"event=/x"}), Error);
  EXPECT_THROW(parseTopicOverrides({"events"}), Error);
  EXPECT_THROW(parseTopicOverrides({"events=x"}), Error);
  EXPECT_THROW(parseTopicOverrides({"imu=/a", "imu=/b"}), Error);
  EXPECT_EQ(topicKindType(TopicKind::kImu), "sensor_msgs/Imu");
  EXPECT_EQ(topicKindMd5(TopicKind::kEvents), "5e8beee5a6c107e504c2e78903c224b8");
}

}  // namespace
}  // namespace evio::bags::detail
