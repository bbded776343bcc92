#include "evio/core/io/track_noise_txt.h"

#include <cmath>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {
namespace {

/// Empty when the covariance is valid, else what is wrong with it. The two
/// off-diagonal entries may differ by rounding (1e-9 of the diagonal).
std::string covarianceProblem(const Mat2& c) {
  if (!c.allFinite()) return "not finite";
  if (std::abs(c(0, 1) - c(1, 0)) > 1e-9 * (std::abs(c(0, 0)) + std::abs(c(1, 1)))) return "not symmetric";
  if (c(0, 0) < 0.0 || c(1, 1) < 0.0 || c(0, 0) * c(1, 1) < c(0, 1) * c(0, 1)) return "not positive semi-definite";
  return {};
}

}  // namespace

void writeTrackNoiseText(const std::string& path, const std::vector<TrackNoiseSample>& samples,
                         const std::vector<std::string>& header) {
  std::string out;
  for (const auto& h : header) out += "# " + h + "\n";
  for (const TrackNoiseSample& s : samples) {
    if (s.id < 0) throw Error::inFile(path, 0, "track ids must be >= 0");
    if (!(s.quality >= 0.0 && s.quality <= 1.0)) throw Error::inFile(path, 0, "quality must lie in [0, 1]");
    if (const std::string problem = covarianceProblem(s.cov_px); !problem.empty())
      throw Error::inFile(path, 0, "covariance of track " + std::to_string(s.id) + " " + problem);
    appendInt(out, s.id);
    out.push_back(' ');
    appendSeconds(out, s.t_ns);
    const double xy = s.cov_px(0, 1) == s.cov_px(1, 0) ? s.cov_px(0, 1) : 0.5 * (s.cov_px(0, 1) + s.cov_px(1, 0));
    for (const double v : {s.quality, s.cov_px(0, 0), xy, s.cov_px(1, 1)}) {
      out.push_back(' ');
      appendDouble(out, v);
    }
    out.push_back('\n');
  }
  writeFileAtomic(path, out);
}

std::vector<TrackNoiseSample> readTrackNoiseText(const std::string& path) {
  static constexpr const char* kColumns[6] = {"id", "t", "quality", "cov_xx", "cov_xy", "cov_yy"};
  LineReader lines(path);
  std::vector<TrackNoiseSample> out;
  std::string_view line;
  std::string_view f[6];
  while (lines.next(line)) {
    if (isBlankOrComment(line)) continue;
    bool more = false;
    const std::size_t n = splitFields(line, f, 6, &more);
    const auto fail = [&](const char* column, const std::string& what) {
      throw Error::inField(lines.path(), lines.lineNumber(), column, what);
    };
    if (n != 6 || more)
      throw Error::inFile(lines.path(), lines.lineNumber(),
                          "expected 6 columns 'id t quality cov_xx cov_xy cov_yy', got " + std::to_string(n) +
                              (more ? "+" : ""));
    TrackNoiseSample s;
    if (!parseInt64(f[0], &s.id) || s.id < 0) fail("id", "not a non-negative integer: '" + std::string(f[0]) + "'");
    if (!parseSecondsToNs(f[1], &s.t_ns)) fail("t", "not a finite time in seconds: '" + std::string(f[1]) + "'");
    double v[4] = {};
    for (int k = 0; k < 4; ++k)
      if (!parseFiniteDouble(f[2 + k], &v[k]))
        fail(kColumns[2 + k], "not a finite number: '" + std::string(f[2 + k]) + "'");
    if (!(v[0] >= 0.0 && v[0] <= 1.0)) fail("quality", "outside [0, 1]: '" + std::string(f[2]) + "'");
    s.quality = v[0];
    s.cov_px << v[1], v[2], v[2], v[3];
    if (const std::string problem = covarianceProblem(s.cov_px); !problem.empty()) fail("cov_xx", problem);
    out.push_back(s);
  }
  return out;
}

}  // namespace evio::io
