#include "evio/core/io/tracks_txt.h"

#include "evio/core/error.h"

namespace evio::io {

TracksReader::TracksReader(std::string path) : lines_(std::move(path)) {}

bool TracksReader::next(TrackSample& s) {
  std::string_view line;
  std::string_view f[4];
  while (lines_.next(line)) {
    if (isBlankOrComment(line)) continue;
    bool more = false;
    const std::size_t n = splitFields(line, f, 4, &more);
    const auto fail = [&](const char* column, const std::string& what) {
      throw Error::inField(lines_.path(), lines_.lineNumber(), column, what);
    };
    if (n != 4 || more)
      throw Error::inFile(lines_.path(), lines_.lineNumber(),
                          "expected 4 columns 'id t x y', got " + std::to_string(n) + (more ? "+" : ""));
    if (!parseInt64(f[0], &s.id) || s.id < 0) fail("id", "not a non-negative integer: '" + std::string(f[0]) + "'");
    if (!parseSecondsToNs(f[1], &s.t_ns)) fail("t", "not a finite time in seconds: '" + std::string(f[1]) + "'");
    double x = 0.0, y = 0.0;
    if (!parseFiniteDouble(f[2], &x)) fail("x", "not a finite number: '" + std::string(f[2]) + "'");
    if (!parseFiniteDouble(f[3], &y)) fail("y", "not a finite number: '" + std::string(f[3]) + "'");
    s.uv = Vec2(x, y);
    auto [it, inserted] = last_t_ns_.try_emplace(s.id, s.t_ns);
    if (!inserted) {
      if (s.t_ns <= it->second)
        fail("t", "time of track " + std::to_string(s.id) + " does not increase");
      it->second = s.t_ns;
    }
    return true;
  }
  return false;
}

std::vector<TrackSample> readTracksText(const std::string& path) {
  TracksReader reader(path);
  std::vector<TrackSample> out;
  TrackSample s;
  while (reader.next(s)) out.push_back(s);
  return out;
}

TracksWriter::TracksWriter(std::string path, const std::vector<std::string>& header) : file_(std::move(path)) {
  for (const auto& h : header) buffer_ += "# " + h + "\n";
}

void TracksWriter::append(const TrackSample& s) {
  if (s.id < 0) throw Error::inFile(file_.path(), 0, "track ids must be >= 0");
  if (!s.uv.allFinite()) throw Error::inFile(file_.path(), 0, "track positions must be finite");
  auto [it, inserted] = last_t_ns_.try_emplace(s.id, s.t_ns);
  if (!inserted) {
    if (s.t_ns <= it->second)
      throw Error::inFile(file_.path(), 0, "time of track " + std::to_string(s.id) + " does not increase");
    it->second = s.t_ns;
  }
  appendInt(buffer_, s.id);
  buffer_.push_back(' ');
  appendSeconds(buffer_, s.t_ns);
  buffer_.push_back(' ');
  appendDouble(buffer_, s.uv.x());
  buffer_.push_back(' ');
  appendDouble(buffer_, s.uv.y());
  buffer_.push_back('\n');
  if (buffer_.size() > (1u << 20)) {
    file_.write(buffer_);
    buffer_.clear();
  }
}

void TracksWriter::close() {
  file_.write(buffer_);
  buffer_.clear();
  file_.commit();
}

void writeTracksText(const std::string& path, const std::vector<TrackSample>& samples,
                     const std::vector<std::string>& header) {
  TracksWriter w(path, header);
  for (const auto& s : samples) w.append(s);
  w.close();
}

}  // namespace evio::io
