#pragma once
/// @file dvs_msgs.h
/// dvs_msgs/Event and dvs_msgs/EventArray of rpg_dvs_ros (the driver of the
/// DAVIS and DVS cameras that recorded the Event-Camera Dataset), defined by
/// evio because Debian packages no dvs_msgs. Published definitions:
///
///   dvs_msgs/Event        uint16 x, uint16 y, time ts, bool polarity
///   dvs_msgs/EventArray   Header header, uint32 height, uint32 width, Event[] events
///
/// Wire format (ROS 1 serialisation, little endian): an Event is 13 bytes,
/// x (2) y (2) ts.sec (4) ts.nsec (4) polarity (1); an EventArray is the
/// header (seq, stamp, frame_id), height, width, a uint32 count and the
/// events. (0, 0) is the top-left pixel; polarity true = brighter.
///
/// The MD5 sums are what ROS computes from the definitions (genmsg: the
/// definition without comments, constants first, a nested type replaced by
/// its own MD5); tests/bags/dvs_msgs_test.py recomputes them with Debian's
/// genmsg and checks the full definition text below against genmsg's.

#include <cstdint>
#include <string>
#include <vector>

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <ros/time.h>
#include <std_msgs/Header.h>

namespace dvs_msgs {

/// One event. `polarity` is ROS's bool, a uint8 on the wire (1 = brighter).
template <class ContainerAllocator>
struct Event_ {
  std::uint16_t x = 0;  ///< column, px
  std::uint16_t y = 0;  ///< row, px
  ros::Time ts;         ///< event time
  std::uint8_t polarity = 0;
};

/// The events of one message, with the sensor size (0 when the sender left it out).
template <class ContainerAllocator>
struct EventArray_ {
  using EventType = Event_<ContainerAllocator>;
  using EventAllocator = typename std::allocator_traits<ContainerAllocator>::template rebind_alloc<EventType>;

  std_msgs::Header_<ContainerAllocator> header;
  std::uint32_t height = 0;  ///< rows, px
  std::uint32_t width = 0;   ///< columns, px
  std::vector<EventType, EventAllocator> events;
};

/// The .msg files of rpg_dvs_ros, byte for byte.
inline constexpr const char* kEventMsgText = "# A DVS event\nuint16 x\nuint16 y\ntime ts\nbool polarity\n";
inline constexpr const char* kEventArrayMsgText =
    "# This message contains an array of events\n"
    "# (0, 0) is at top-left corner of image\n"
    "#\n"
    "\n"
    "Header header\n"
    "\n"
    "uint32 height         # image height, that is, number of rows\n"
    "uint32 width          # image width, that is, number of columns\n"
    "\n"
    "# an array of events\n"
    "Event[] events\n";

/// MD5 of "uint16 x\nuint16 y\ntime ts\nbool polarity".
inline constexpr const char* kEventMd5 = "40d339b261445b8ce9a6fef01267cd5d";
/// MD5 of "<MD5 of std_msgs/Header> header\nuint32 height\nuint32 width\n<kEventMd5> events".
inline constexpr const char* kEventArrayMd5 = "5e8beee5a6c107e504c2e78903c224b8";

/// The full definition stored in a bag's connection header, built as genmsg
/// does: the message's text, then for every nested type (in order of first
/// use) a line of 80 '=', "MSG: <type>" and its text; the final newline dropped.
std::string eventArrayFullDefinition();
std::string eventFullDefinition();

}  // namespace dvs_msgs

namespace ros::message_traits {

template <class A>
struct MD5Sum<dvs_msgs::Event_<A>> {
  static const char* value() { return dvs_msgs::kEventMd5; }
  static const char* value(const dvs_msgs::Event_<A>&) { return value(); }
  static const std::uint64_t static_value1 = 0x40d339b261445b8cULL;
  static const std::uint64_t static_value2 = 0xe9a6fef01267cd5dULL;
};
template <class A>
struct DataType<dvs_msgs::Event_<A>> {
  static const char* value() { return "dvs_msgs/Event"; }
  static const char* value(const dvs_msgs::Event_<A>&) { return value(); }
};
template <class A>
struct Definition<dvs_msgs::Event_<A>> {
  static const char* value() {
    static const std::string text = dvs_msgs::eventFullDefinition();
    return text.c_str();
  }
  static const char* value(const dvs_msgs::Event_<A>&) { return value(); }
};
template <class A>
struct IsFixedSize<dvs_msgs::Event_<A>> : TrueType {};

template <class A>
struct MD5Sum<dvs_msgs::EventArray_<A>> {
  static const char* value() { return dvs_msgs::kEventArrayMd5; }
  static const char* value(const dvs_msgs::EventArray_<A>&) { return value(); }
  static const std::uint64_t static_value1 = 0x5e8beee5a6c107e5ULL;
  static const std::uint64_t static_value2 = 0x04c2e78903c224b8ULL;
};
template <class A>
struct DataType<dvs_msgs::EventArray_<A>> {
  static const char* value() { return "dvs_msgs/EventArray"; }
  static const char* value(const dvs_msgs::EventArray_<A>&) { return value(); }
};
template <class A>
struct Definition<dvs_msgs::EventArray_<A>> {
  static const char* value() {
    static const std::string text = dvs_msgs::eventArrayFullDefinition();
    return text.c_str();
  }
  static const char* value(const dvs_msgs::EventArray_<A>&) { return value(); }
};
template <class A>
struct HasHeader<dvs_msgs::EventArray_<A>> : TrueType {};

}  // namespace ros::message_traits

namespace ros::serialization {

/// Fields in the order of the definition; ROS serialises bool as one byte.
template <class A>
struct Serializer<dvs_msgs::Event_<A>> {
  template <typename Stream, typename M>
  inline static void allInOne(Stream& stream, M m) {
    stream.next(m.x);
    stream.next(m.y);
    stream.next(m.ts);
    stream.next(m.polarity);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};

template <class A>
struct Serializer<dvs_msgs::EventArray_<A>> {
  template <typename Stream, typename M>
  inline static void allInOne(Stream& stream, M m) {
    stream.next(m.header);
    stream.next(m.height);
    stream.next(m.width);
    stream.next(m.events);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};

}  // namespace ros::serialization
