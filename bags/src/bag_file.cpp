#include "bag_file.h"

#include <console_bridge/console.h>
#include <ros/serialization.h>
#include <rosbag/exceptions.h>

#include <exception>
#include <filesystem>
#include <fstream>
#include <new>

#include "evio/core/error.h"

namespace evio::bags::detail {

namespace fs = std::filesystem;

void silenceRosLogging() { console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE); }

namespace {

/// "<bag>: <context>: <message>", leaving out an empty context. Control
/// characters (a damaged bag's topic name may hold a newline) become '?',
/// so the error stays one line.
Error bagError(const std::string& bag, const std::string& context, const std::string& message) {
  std::string text = bag + ": " + (context.empty() ? "" : context + ": ") + message;
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return Error(text);
}

/// The first line of a ROS 1 bag is "#ROSBAG V2.0" (version 1.2 and older are
/// another format that librosbag_storage reads only partly).
void requireBagVersion2(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char line[13] = {};
  in.read(line, sizeof(line));
  const std::string first(line, static_cast<std::size_t>(in.gcount()));
  if (first.rfind("#ROSBAG V", 0) != 0) throw Error(path + ": not a ROS 1 bag (it does not start with #ROSBAG V2.0)");
  if (first != "#ROSBAG V2.0\n")
    throw Error(path + ": ROS bag version '" + first.substr(9, first.find('\n') - 9) + "': only version 2.0 is read");
}

}  // namespace

void rethrowAsError(const std::string& bag, const std::string& context) {
  try {
    throw;
  } catch (const Error& e) {
    throw bagError(bag, context, e.what());
  } catch (const rosbag::BagUnindexedException&) {
    throw bagError(bag, context, "truncated or unindexed bag: no index at its end (rosbag reindex repairs a bag cut off while recording)");
  } catch (const rosbag::BagFormatException& e) {
    throw bagError(bag, context, std::string("not a valid ROS 1 bag (version 2.0): ") + e.what());
  } catch (const rosbag::BagIOException& e) {
    throw bagError(bag, context, std::string("truncated or unreadable bag: ") + e.what());
  } catch (const ros::serialization::StreamOverrunException& e) {
    throw bagError(bag, context, std::string("message shorter than its type needs (corrupt data or a wrong type): ") + e.what());
  } catch (const rosbag::BagException& e) {
    throw bagError(bag, context, std::string("corrupt bag (damaged record or compressed chunk): ") + e.what());
  } catch (const std::bad_alloc&) {
    throw bagError(bag, context, "corrupt bag: a length field asks for more memory than there is");
  } catch (const std::length_error&) {
    throw bagError(bag, context, "corrupt bag: a length field is out of range");
  } catch (const std::exception& e) {
    throw bagError(bag, context, std::string("cannot read the bag: ") + e.what());
  }
}

void openForReading(rosbag::Bag& bag, const std::string& path) {
  silenceRosLogging();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
  requireBagVersion2(path);
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (...) {
    rethrowAsError(path, "");
  }
}

}  // namespace evio::bags::detail
