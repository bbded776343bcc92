#include "evio/core/io/calib_txt.h"

#include <array>
#include <charconv>
#include <cmath>
#include <system_error>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"

namespace evio::io {

namespace {

constexpr std::array<const char*, 9> kColumnNames = {"fx", "fy", "cx", "cy", "k1",
                                                     "k2", "p1", "p2", "k3"};

std::string columnField(std::size_t i) {
  return "column " + std::to_string(i + 1) + " (" + kColumnNames[i] + ")";
}

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::vector<std::string_view> splitWhitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSpace(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

void appendShortest(std::string& out, double v) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  if (ec != std::errc()) throw Error("calib.txt: cannot format a number");
  out.append(buf, end);
}

}  // namespace

CalibTxt parseCalibTxt(std::string_view text, const std::string& name) {
  std::vector<double> values;
  std::int64_t data_line = 0;
  std::int64_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const auto tokens = splitWhitespace(line);
    if (tokens.empty() || tokens.front().front() == '#') continue;
    if (data_line != 0)
      throw Error::inFile(name, line_no,
                          "unexpected extra line (calib.txt holds one line, the first is line " +
                              std::to_string(data_line) + ")");
    data_line = line_no;
    if (tokens.size() != 9 && tokens.size() != 4)
      throw Error::inFile(name, line_no,
                          "expected 9 values (fx fy cx cy k1 k2 p1 p2 k3) or 4 (fx fy cx cy), got " +
                              std::to_string(tokens.size()));
    for (std::size_t i = 0; i < tokens.size(); ++i) {
      const std::string_view tok = tokens[i];
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (ec == std::errc::result_out_of_range)
        throw Error::inField(name, line_no, columnField(i),
                             "number out of range: '" + std::string(tok) + "'");
      if (ec != std::errc() || ptr != tok.data() + tok.size())
        throw Error::inField(name, line_no, columnField(i),
                             "expected a number, got '" + std::string(tok) + "'");
      if (!std::isfinite(v))
        throw Error::inField(name, line_no, columnField(i),
                             "must be finite, got '" + std::string(tok) + "'");
      if (i < 2 && !(v > 0.0))
        throw Error::inField(name, line_no, columnField(i),
                             "focal length must be > 0, got '" + std::string(tok) + "'");
      values.push_back(v);
    }
  }
  if (data_line == 0)
    throw Error::inFile(name, 0, "no calibration line (expected fx fy cx cy k1 k2 p1 p2 k3)");
  CalibTxt calib;
  calib.intrinsics = Vec4(values[0], values[1], values[2], values[3]);
  calib.distortion.resize(static_cast<Eigen::Index>(values.size() - 4));
  for (std::size_t i = 4; i < values.size(); ++i)
    calib.distortion[static_cast<Eigen::Index>(i - 4)] = values[i];
  return calib;
}

CalibTxt readCalibTxt(const std::string& path) { return parseCalibTxt(readFile(path), path); }

std::string formatCalibTxt(const CalibTxt& calib) {
  if (calib.distortion.size() != 0 && calib.distortion.size() != 5)
    throw Error("calib.txt: distortion must have 0 or 5 coefficients (k1 k2 p1 p2 k3), got " +
                std::to_string(calib.distortion.size()));
  std::vector<double> values(calib.intrinsics.data(), calib.intrinsics.data() + 4);
  for (Eigen::Index i = 0; i < calib.distortion.size(); ++i) values.push_back(calib.distortion[i]);
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw Error("calib.txt: " + columnField(i) + ": must be finite");
    if (i > 0) out.push_back(' ');
    appendShortest(out, values[i]);
  }
  out.push_back('\n');
  return out;
}

void writeCalibTxt(const std::string& path, const CalibTxt& calib) {
  writeFileAtomic(path, formatCalibTxt(calib));
}

CalibTxt calibTxtFromCamera(const Camera& camera) {
  CalibTxt calib;
  calib.intrinsics = camera.intrinsics();
  if (camera.as<PinholeCamera>()) {
    calib.distortion = VecX::Zero(5);
  } else if (camera.as<RadTanCamera>()) {
    calib.distortion = camera.distortion();
  } else {
    throw Error("calib.txt: cannot express a camera of model '" + std::string(camera.model()) +
                "' (only pinhole and radtan)");
  }
  return calib;
}

Camera cameraFromCalibTxt(const CalibTxt& calib, int width, int height) {
  const bool pinhole = calib.distortion.size() == 0 || (calib.distortion.array() == 0.0).all();
  if (pinhole) return Camera::create(PinholeCamera::kModelName, width, height, calib.intrinsics, VecX());
  return Camera::create(RadTanCamera::kModelName, width, height, calib.intrinsics, calib.distortion);
}

}  // namespace evio::io
