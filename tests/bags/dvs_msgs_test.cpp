// dvs_msgs as the project defines it: the wire bytes of rpg_dvs_ros's layout,
// the published MD5 sums and the full definition stored in a bag. (The MD5
// is recomputed from the .msg texts by Debian's genmsg in bags_test.py.)
#include "evio/bags/ros/dvs_msgs.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "evio/bags/ros/ros_messages.h"

namespace evio::bags {
namespace {

using EventArray = dvs_msgs::EventArray_<RosAllocator<void>>;
using Event = dvs_msgs::Event_<RosAllocator<void>>;

std::vector<std::uint8_t> serialise(const EventArray& msg) {
  const std::uint32_t n = ros::serialization::serializationLength(msg);
  std::vector<std::uint8_t> bytes(n);
  ros::serialization::OStream stream(bytes.data(), n);
  ros::serialization::serialize(stream, msg);
  return bytes;
}

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void putU16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}

TEST(DvsMsgs, WireBytesAreThePublishedLayout) {
  EventArray msg;
  msg.header.seq = 7;
  msg.header.stamp = ros::Time(1468939993, 67416301);
  msg.header.frame_id = "dvs";
  msg.height = 180;
  msg.width = 240;
  Event a;
  a.x = 239, a.y = 3, a.ts = ros::Time(1468939993, 999999999), a.polarity = 1;
  Event b;
  b.x = 0, b.y = 179, b.ts = ros::Time(1468939994, 0), b.polarity = 0;
  msg.events = {a, b};

  std::vector<std::uint8_t> expected;  // little endian, no padding
  putU32(expected, 7);
  putU32(expected, 1468939993);
  putU32(expected, 67416301);
  putU32(expected, 3);
  for (char c : std::string("dvs")) expected.push_back(static_cast<std::uint8_t>(c));
  putU32(expected, 180);
  putU32(expected, 240);
  putU32(expected, 2);
  for (const Event& e : {a, b}) {
    putU16(expected, e.x);
    putU16(expected, e.y);
    putU32(expected, e.ts.sec);
    putU32(expected, e.ts.nsec);
    expected.push_back(e.polarity);
  }
  ASSERT_EQ(expected.size(), 12u + 4 + 3 + 12 + 2 * 13u);
  EXPECT_EQ(serialise(msg), expected);

  EventArray back;
  auto bytes = serialise(msg);
  ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::deserialize(in, back);
  ASSERT_EQ(back.events.size(), 2u);
  EXPECT_EQ(back.events[0].ts, a.ts);
  EXPECT_EQ(back.events[1].y, 179);
  EXPECT_EQ(back.header.frame_id, "dvs");
}

TEST(DvsMsgs, ShortBytesAreAnOverrunNotAnAccess) {
  EventArray msg;
  msg.events.resize(3);
  auto bytes = serialise(msg);
  bytes.resize(bytes.size() - 5);
  ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  EventArray back;
  EXPECT_THROW(ros::serialization::deserialize(in, back), ros::serialization::StreamOverrunException);
}

TEST(DvsMsgs, TraitsCarryThePublishedSums) {
  using ros::message_traits::MD5Sum;
  EXPECT_STREQ(MD5Sum<EventArray>::value(), "5e8beee5a6c107e504c2e78903c224b8");
  EXPECT_STREQ(MD5Sum<Event>::value(), "40d339b261445b8ce9a6fef01267cd5d");
  // The two 64-bit halves ROS compares on the wire agree with the text.
  char text[33];
  std::snprintf(text, sizeof(text), "%016llx%016llx",
                static_cast<unsigned long long>(MD5Sum<EventArray>::static_value1),
                static_cast<unsigned long long>(MD5Sum<EventArray>::static_value2));
  EXPECT_STREQ(text, MD5Sum<EventArray>::value());
  std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(MD5Sum<Event>::static_value1),
                static_cast<unsigned long long>(MD5Sum<Event>::static_value2));
  EXPECT_STREQ(text, MD5Sum<Event>::value());
  EXPECT_STREQ(ros::message_traits::DataType<EventArray>::value(), "dvs_msgs/EventArray");
  EXPECT_TRUE(ros::message_traits::HasHeader<EventArray>::value);
}

TEST(DvsMsgs, FullDefinitionNestsHeaderThenEvent) {
  const std::string def = ros::message_traits::Definition<EventArray>::value();
  const std::string sep(80, '=');
  EXPECT_EQ(def.rfind(dvs_msgs::kEventArrayMsgText, 0), 0u);
  const auto header = def.find(sep + "\nMSG: std_msgs/Header\n");
  const auto event = def.find(sep + "\nMSG: dvs_msgs/Event\n" + dvs_msgs::kEventMsgText);
  ASSERT_NE(header, std::string::npos);
  ASSERT_NE(event, std::string::npos);
  EXPECT_LT(header, event);
  EXPECT_EQ(event + sep.size() + std::strlen("\nMSG: dvs_msgs/Event\n") + std::strlen(dvs_msgs::kEventMsgText),
            def.size());
  EXPECT_EQ(std::string(ros::message_traits::Definition<Event>::value()), dvs_msgs::kEventMsgText);
}

}  // namespace
}  // namespace evio::bags
