#include "evio/core/io/track_points_txt.h"

#include <unordered_set>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {

std::vector<TrackPoint> readTrackPoints(const std::string& path) {
  LineReader lines(path);
  std::vector<TrackPoint> out;
  std::unordered_set<std::int64_t> ids;
  std::string_view line;
  std::string_view f[4];
  static constexpr const char* kColumns[3] = {"px", "py", "pz"};
  while (lines.next(line)) {
    if (isBlankOrComment(line)) continue;
    bool more = false;
    const std::size_t n = splitFields(line, f, 4, &more);
    if (n != 4 || more)
      throw Error::inFile(path, lines.lineNumber(),
                          "expected 4 columns 'id px py pz', got " + std::to_string(n) + (more ? "+" : ""));
    TrackPoint p;
    if (!parseInt64(f[0], &p.id) || p.id < 0)
      throw Error::inField(path, lines.lineNumber(), "id", "not a non-negative integer: '" + std::string(f[0]) + "'");
    if (!ids.insert(p.id).second)
      throw Error::inField(path, lines.lineNumber(), "id", "repeated id " + std::to_string(p.id));
    for (int k = 0; k < 3; ++k)
      if (!parseFiniteDouble(f[k + 1], &p.p_W[k]))
        throw Error::inField(path, lines.lineNumber(), kColumns[k],
                             "not a finite number: '" + std::string(f[k + 1]) + "'");
    out.push_back(p);
  }
  return out;
}

void writeTrackPoints(const std::string& path, const std::vector<TrackPoint>& points,
                      const std::vector<std::string>& header) {
  std::string text;
  for (const auto& h : header) text += "# " + h + "\n";
  std::unordered_set<std::int64_t> ids;
  for (const auto& p : points) {
    if (p.id < 0 || !ids.insert(p.id).second)
      throw Error::inFile(path, 0, "track point ids must be non-negative and unique (id " + std::to_string(p.id) + ")");
    if (!p.p_W.allFinite()) throw Error::inFile(path, 0, "track point " + std::to_string(p.id) + " is not finite");
    appendInt(text, p.id);
    for (int k = 0; k < 3; ++k) {
      text.push_back(' ');
      appendDouble(text, p.p_W[k]);
    }
    text.push_back('\n');
  }
  writeFileAtomic(path, text);
}

}  // namespace evio::io
