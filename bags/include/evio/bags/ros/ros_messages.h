#pragma once
/// @file ros_messages.h
/// The ROS 1 message types evio reads and writes, from Debian's generated
/// headers (sensor_msgs, geometry_msgs, std_msgs) and the project's own
/// dvs_msgs (dvs_msgs.h).
///
/// Why an allocator of our own: the generated headers name
/// `ContainerAllocator::template rebind<T>::other`, and C++20 removed
/// `std::allocator<void>::rebind`, so `sensor_msgs::Imu` (that is
/// `Imu_<std::allocator<void>>`) does not compile in this C++20 project.
/// `RosAllocator<void>` has the member `rebind` back. The
/// serialised bytes, MD5 sums and definitions do not depend on the allocator
/// (the traits are templates over it), so these types read and write the
/// same messages as any other ROS 1 program.
///
/// This header includes ROS headers; only the bags module and its tests see it.

#include <memory>
#include <type_traits>

#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/String.h>

namespace evio::bags {

/// The allocator the message templates are instantiated with: std::allocator
/// plus the member `rebind` that the generated code and roscpp's vector
/// serialiser ask for. Strings rebind to std::allocator<char>, so every
/// string field is a plain std::string; vectors keep RosAllocator (roscpp
/// rebinds their allocator again) and behave as std::vector.
template <class T>
struct RosAllocator : std::allocator<T> {
  RosAllocator() = default;
  template <class U>
  RosAllocator(const RosAllocator<U>&) noexcept {}  // NOLINT: converting, as std::allocator's
  template <class U>
  struct rebind {
    using other = std::conditional_t<std::is_same_v<U, char>, std::allocator<char>, RosAllocator<U>>;
  };
};

template <class T, class U>
bool operator==(const RosAllocator<T>&, const RosAllocator<U>&) noexcept {
  return true;
}

using RosImu = sensor_msgs::Imu_<RosAllocator<void>>;
using RosImage = sensor_msgs::Image_<RosAllocator<void>>;
using RosCameraInfo = sensor_msgs::CameraInfo_<RosAllocator<void>>;
using RosPoseStamped = geometry_msgs::PoseStamped_<RosAllocator<void>>;
using RosString = std_msgs::String_<RosAllocator<void>>;

}  // namespace evio::bags
