#include "evio/bags/ros/dvs_msgs.h"

#include <std_msgs/Header.h>

#include "evio/bags/ros/ros_messages.h"

namespace dvs_msgs {

namespace {

/// genmsg's separator between a message and each nested definition.
std::string nestedBlock(const char* type, const std::string& text) {
  return std::string(80, '=') + "\nMSG: " + type + "\n" + text + "\n";
}

std::string dropLastChar(std::string s) {
  if (!s.empty()) s.pop_back();
  return s;
}

}  // namespace

std::string eventFullDefinition() { return dropLastChar(std::string(kEventMsgText) + "\n"); }

std::string eventArrayFullDefinition() {
  using Header = std_msgs::Header_<evio::bags::RosAllocator<void>>;
  const std::string header_text = ros::message_traits::Definition<Header>::value();
  return dropLastChar(std::string(kEventArrayMsgText) + "\n" + nestedBlock("std_msgs/Header", header_text) +
                      nestedBlock("dvs_msgs/Event", kEventMsgText));
}

}  // namespace dvs_msgs
