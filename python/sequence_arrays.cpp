#include "sequence_arrays.h"

#include <pybind11/eval.h>
#include <pybind11/stl.h>

#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/tum.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace evio::python {

namespace {

#pragma pack(push, 1)
struct PackedEvent {
  std::int64_t t;
  std::uint16_t x, y;
  std::uint8_t p;
};
struct PackedImu {
  std::int64_t t;
  double gyro[3];
  double acc[3];
};
struct PackedPose {
  std::int64_t t;
  double p[3];
  double q[4];
};
#pragma pack(pop)
static_assert(sizeof(PackedEvent) == 13 && sizeof(PackedImu) == 56 && sizeof(PackedPose) == 64);

/// A NumPy array over a vector moved to the heap; the capsule frees it.
template <class T>
py::array ownedArray(std::vector<T>&& values) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(static_cast<py::ssize_t>(owned->size()), owned->data(), free_when_done);
}

std::string requireFile(const std::string& folder, const std::string& name) {
  const fs::path p = fs::path(folder) / name;
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) throw Error(p.string() + ": no such file in the sequence folder");
  return p.string();
}

py::dtype dtypeOf(const char* spec_python) { return py::dtype::from_args(py::eval(spec_python)); }

}  // namespace

struct EventChunks::Reader {
  std::unique_ptr<io::EventH5Reader> h5;
  std::unique_ptr<io::EventTextReader> txt;
  bool next(EventArray& out, std::size_t n) { return h5 ? h5->next(out, n) : txt->next(out, n); }
};

EventChunks::EventChunks(const std::string& folder, std::size_t chunk, TimeWindow window)
    : reader_(std::make_unique<Reader>()), chunk_(chunk), window_(window) {
  if (chunk == 0) throw Error("chunk_size: must be > 0");
  if (window.t_start_ns && window.t_end_ns && *window.t_end_ns < *window.t_start_ns)
    throw Error("t_end_ns: must be >= t_start_ns");
  std::error_code ec;
  if (fs::is_regular_file(fs::path(folder) / "events.h5", ec))
    reader_->h5 = std::make_unique<io::EventH5Reader>((fs::path(folder) / "events.h5").string());
  else
    reader_->txt = std::make_unique<io::EventTextReader>(requireFile(folder, "events.txt"));
}

EventChunks::~EventChunks() = default;

bool EventChunks::next(EventArray& out) {
  out.clear();
  while (!done_ && out.empty()) {
    if (!reader_->next(out, chunk_)) {
      done_ = true;
      break;
    }
    // Keep [t_start, t_end): time is non-decreasing, so trim both ends by binary search.
    const std::size_t begin = window_.t_start_ns ? out.lowerBound(*window_.t_start_ns) : 0;
    std::size_t end = out.size();
    if (window_.t_end_ns) {
      end = out.lowerBound(*window_.t_end_ns);
      if (end < out.size()) done_ = true;  // nothing later can fall inside
    }
    out.keepRange(begin, end);
  }
  return !out.empty();
}

py::dtype eventDtype() { return dtypeOf("[('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', 'u1')]"); }

py::array eventsToStructured(const EventArray& events) {
  py::array out(eventDtype(), std::vector<py::ssize_t>{static_cast<py::ssize_t>(events.size())});
  auto* dst = static_cast<PackedEvent*>(out.mutable_data());
  for (std::size_t i = 0; i < events.size(); ++i)
    dst[i] = PackedEvent{events.t()[i], events.x()[i], events.y()[i], events.p()[i]};
  return out;
}

py::dict eventsToColumns(EventArray&& events) {
  py::dict columns;
  columns["t"] = ownedArray(std::move(events.t()));
  columns["x"] = ownedArray(std::move(events.x()));
  columns["y"] = ownedArray(std::move(events.y()));
  columns["p"] = ownedArray(std::move(events.p()));
  return columns;
}

py::array readImu(const std::string& folder) {
  const ImuSamples samples = io::readImuText(requireFile(folder, "imu.txt"));
  py::array out(dtypeOf("[('t', '<i8'), ('gyro', '<f8', (3,)), ('acc', '<f8', (3,))]"),
                std::vector<py::ssize_t>{static_cast<py::ssize_t>(samples.size())});
  auto* dst = static_cast<PackedImu*>(out.mutable_data());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const ImuSample& s = samples[i];
    dst[i] = PackedImu{s.t_ns, {s.gyro_B.x(), s.gyro_B.y(), s.gyro_B.z()}, {s.acc_B.x(), s.acc_B.y(), s.acc_B.z()}};
  }
  return out;
}

py::array readGroundtruth(const std::string& folder) {
  const Trajectory poses = io::readTum(requireFile(folder, "groundtruth.txt"));
  py::array out(dtypeOf("[('t', '<i8'), ('p', '<f8', (3,)), ('q', '<f8', (4,))]"),
                std::vector<py::ssize_t>{static_cast<py::ssize_t>(poses.size())});
  auto* dst = static_cast<PackedPose*>(out.mutable_data());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Vec3& p = poses[i].pose.translation();
    const Quat& q = poses[i].pose.quaternion();
    dst[i] = PackedPose{poses[i].t_ns, {p.x(), p.y(), p.z()}, {q.x(), q.y(), q.z(), q.w()}};
  }
  return out;
}

namespace {

/// Python iterator over event chunks (structured arrays).
class EventIterator {
 public:
  EventIterator(const std::string& folder, std::size_t chunk, TimeWindow w) : chunks_(folder, chunk, w) {}
  py::array next() {
    EventArray chunk;
    bool more = false;
    {
      py::gil_scoped_release unlocked;
      more = chunks_.next(chunk);
    }
    if (!more) throw py::stop_iteration();
    return eventsToStructured(chunk);
  }

 private:
  EventChunks chunks_;
};

/// Python iterator over frames: (t_ns, uint8 array H×W) one at a time.
class FrameIterator {
 public:
  explicit FrameIterator(const std::string& folder) : folder_(folder), stamps_(io::readImageList(folder)) {}
  py::tuple next() {
    if (index_ >= stamps_.size()) throw py::stop_iteration();
    const io::ImageStamp& s = stamps_[index_++];
    cv::Mat image = io::readFrame(folder_, s);
    if (!image.isContinuous()) image = image.clone();
    auto* owned = new cv::Mat(image);  // the array keeps the pixels alive; no copy
    py::capsule free_when_done(owned, [](void* p) { delete static_cast<cv::Mat*>(p); });
    py::array_t<std::uint8_t> pixels({owned->rows, owned->cols}, owned->ptr<std::uint8_t>(), free_when_done);
    return py::make_tuple(s.t_ns, pixels);
  }

 private:
  std::string folder_;
  std::vector<io::ImageStamp> stamps_;
  std::size_t index_ = 0;
};

EventArray readWindow(const std::string& folder, TimeWindow w) {
  py::gil_scoped_release unlocked;
  EventChunks chunks(folder, std::size_t{1} << 20, w);
  EventArray all, chunk;
  while (chunks.next(chunk)) all.append(chunk);
  return all;
}

}  // namespace

void addSequenceReaders(py::module_& m) {
  using py::arg;
  py::class_<EventIterator>(m, "EventIterator")
      .def("__iter__", [](EventIterator& it) -> EventIterator& { return it; })
      .def("__next__", &EventIterator::next);
  py::class_<FrameIterator>(m, "FrameIterator")
      .def("__iter__", [](FrameIterator& it) -> FrameIterator& { return it; })
      .def("__next__", &FrameIterator::next);

  m.def(
      "read_events",
      [](const std::string& folder, std::optional<std::int64_t> t0, std::optional<std::int64_t> t1) {
        return eventsToStructured(readWindow(folder, {t0, t1}));
      },
      arg("folder"), arg("t_start_ns") = py::none(), arg("t_end_ns") = py::none(),
      "Events of a sequence folder in [t_start_ns, t_end_ns) as a structured array (t, x, y, p).");
  m.def(
      "read_event_columns",
      [](const std::string& folder, std::optional<std::int64_t> t0, std::optional<std::int64_t> t1) {
        return eventsToColumns(readWindow(folder, {t0, t1}));
      },
      arg("folder"), arg("t_start_ns") = py::none(), arg("t_end_ns") = py::none(),
      "The same as read_events, as a dict of column arrays t, x, y, p that own the reader's buffers (no copy).");
  m.def(
      "iter_events",
      [](const std::string& folder, std::size_t chunk, std::optional<std::int64_t> t0,
         std::optional<std::int64_t> t1) { return std::make_unique<EventIterator>(folder, chunk, TimeWindow{t0, t1}); },
      arg("folder"), arg("chunk_size") = std::size_t{1} << 20, arg("t_start_ns") = py::none(),
      arg("t_end_ns") = py::none(),
      "Streams the events in structured arrays of at most chunk_size events: memory stays flat.");
  m.def("iter_frames", [](const std::string& folder) { return std::make_unique<FrameIterator>(folder); }, arg("folder"),
        "Streams the frames of images.txt as (t_ns, uint8 array of shape (height, width)).");
  m.def("read_imu", &readImu, arg("folder"), "imu.txt as a structured array (t, gyro[3], acc[3]).");
  m.def("read_groundtruth", &readGroundtruth, arg("folder"),
        "groundtruth.txt as a structured array (t, p[3], q[4] as x y z w).");
}

}  // namespace evio::python
