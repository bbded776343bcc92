#include "evio/core/io/sensors_yaml.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <initializer_list>
#include <set>
#include <string_view>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/so3.h"

namespace evio::io {

namespace {

using config::Document;
using config::scalarAs;
using config::throwAt;

constexpr double kOrthonormalTolerance = 1e-6;
constexpr double kLastRowTolerance = 1e-12;
constexpr double kMaxTimeshiftS = 1e5;  // |t| * 1e9 stays exactly representable in ns

std::string indexed(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

/// A YAML map with a fixed set of allowed keys; reports unknown, duplicate
/// and missing keys with file:line.
class MapView {
 public:
  MapView(const Document& doc, const YAML::Node& node, std::string path,
          std::initializer_list<const char*> keys)
      : doc_(doc), node_(node), path_(std::move(path)) {
    if (!node_.IsMap()) throwAt(doc_, node_, path_.empty() ? "<top level>" : path_, "expected a map");
    std::set<std::string> allowed(keys.begin(), keys.end());
    std::set<std::string> seen;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      const std::string key = it->first.Scalar();
      if (!allowed.count(key)) {
        std::string known;
        for (const char* k : keys) known += (known.empty() ? "" : ", ") + std::string(k);
        throwAt(doc_, it->first, join(key), "unknown key (known keys: " + known + ")");
      }
      if (!seen.insert(key).second) throwAt(doc_, it->first, join(key), "duplicate key");
    }
  }

  /// The value of `key`; throws at the map's line when it is absent or null.
  YAML::Node required(const char* key) const {
    YAML::Node v = node_[key];
    if (!v.IsDefined() || v.IsNull())
      throwAt(doc_, node_, join(key), "missing required key '" + std::string(key) + "'");
    return v;
  }

  /// The value of `key`, or an undefined node when absent or null.
  YAML::Node optional(const char* key) const {
    YAML::Node v = node_[key];
    if (v.IsDefined() && v.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
    return v;
  }

  std::string join(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  double finite(const char* key) const { return finiteAt(required(key), join(key)); }
  double finiteAt(const YAML::Node& v, const std::string& path) const {
    const double x = scalarAs<double>(doc_, v, path);
    if (!std::isfinite(x)) throwAt(doc_, v, path, "must be finite");
    return x;
  }
  double nonNegative(const char* key) const {
    const YAML::Node v = required(key);
    const double x = finiteAt(v, join(key));
    if (x < 0.0) throwAt(doc_, v, join(key), "must be >= 0 (got " + v.Scalar() + ")");
    return x;
  }
  double positive(const char* key) const {
    const YAML::Node v = required(key);
    const double x = finiteAt(v, join(key));
    if (!(x > 0.0)) throwAt(doc_, v, join(key), "must be > 0 (got " + v.Scalar() + ")");
    return x;
  }
  std::string string(const char* key) const {
    return scalarAs<std::string>(doc_, required(key), join(key));
  }

  /// A list of finite numbers; `expected_size` < 0 accepts any length.
  VecX numbers(const YAML::Node& v, const std::string& path, int expected_size) const {
    if (!v.IsSequence()) throwAt(doc_, v, path, "expected a list of numbers");
    if (expected_size >= 0 && v.size() != static_cast<std::size_t>(expected_size))
      throwAt(doc_, v, path,
              "expected " + std::to_string(expected_size) + " numbers, got " +
                  std::to_string(v.size()));
    VecX out(static_cast<Eigen::Index>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i)
      out[static_cast<Eigen::Index>(i)] = finiteAt(v[i], indexed(path, i));
    return out;
  }

  const Document& doc() const { return doc_; }
  const YAML::Node& node() const { return node_; }
  const std::string& path() const { return path_; }

 private:
  const Document& doc_;
  YAML::Node node_;
  std::string path_;
};

/// A 4×4 rigid transform: 4 rows of 4 numbers, or 16 numbers row-major.
Pose readRigidTransform(const MapView& map, const char* key) {
  const Document& doc = map.doc();
  const YAML::Node node = map.required(key);
  const std::string path = map.join(key);
  Mat4 T;
  const auto element = [&](const YAML::Node& v, const std::string& p) {
    const double x = scalarAs<double>(doc, v, p);
    if (!std::isfinite(x)) throwAt(doc, v, p, "must be finite");
    return x;
  };
  const char* shape = "expected a 4x4 matrix: 4 rows of 4 numbers (or 16 numbers, row-major)";
  if (!node.IsSequence()) throwAt(doc, node, path, shape);
  if (node.size() == 4) {
    for (std::size_t r = 0; r < 4; ++r) {
      const YAML::Node row = node[r];
      if (!row.IsSequence() || row.size() != 4) throwAt(doc, row, indexed(path, r), shape);
      for (std::size_t c = 0; c < 4; ++c)
        T(static_cast<int>(r), static_cast<int>(c)) =
            element(row[c], indexed(indexed(path, r), c));
    }
  } else if (node.size() == 16) {
    for (std::size_t i = 0; i < 16; ++i)
      T(static_cast<int>(i / 4), static_cast<int>(i % 4)) = element(node[i], indexed(path, i));
  } else {
    throwAt(doc, node, path, shape);
  }
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > kLastRowTolerance)
    throwAt(doc, node, path, "not a rigid transform: the last row must be 0 0 0 1");
  const Mat3 R = T.topLeftCorner<3, 3>();
  const double err = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(err <= kOrthonormalTolerance)) {
    throwAt(doc, node, path,
            "not a rigid transform: rotation block is not orthonormal (max |R^T R - I| = " +
                std::to_string(err) + " > 1e-6)");
  }
  if (!(R.determinant() > 0.0))
    throwAt(doc, node, path, "not a rigid transform: rotation block is a reflection (det < 0)");
  return Pose(so3::orthonormalize(R), Vec3(T.topRightCorner<3, 1>()));
}

CameraSensor readCamera(const Document& doc, const YAML::Node& node, const std::string& path) {
  const MapView map(doc, node, path,
                    {"name", "role", "model", "resolution", "intrinsics", "distortion_coeffs",
                     "T_B_C", "parameters"});
  const std::string name = map.string("name");
  if (name.empty()) throwAt(doc, map.required("name"), map.join("name"), "must not be empty");

  CameraRole role = CameraRole::kEvent;
  try {
    role = parseCameraRole(map.string("role"));
  } catch (const Error& e) {
    throwAt(doc, map.required("role"), map.join("role"), e.what());
  }

  const std::string model = map.string("model");
  const YAML::Node resolution = map.required("resolution");
  if (!resolution.IsSequence() || resolution.size() != 2)
    throwAt(doc, resolution, map.join("resolution"), "expected [width, height] in pixels");
  const int width = scalarAs<int>(doc, resolution[0], map.join("resolution") + "[0]");
  const int height = scalarAs<int>(doc, resolution[1], map.join("resolution") + "[1]");
  const YAML::Node intrinsics_node = map.required("intrinsics");
  const Vec4 intrinsics = map.numbers(intrinsics_node, map.join("intrinsics"), 4);
  const YAML::Node distortion_node = map.optional("distortion_coeffs");
  const VecX distortion = distortion_node.IsDefined()
                              ? map.numbers(distortion_node, map.join("distortion_coeffs"), -1)
                              : VecX();
  std::optional<Camera> camera;
  try {
    camera = Camera::create(model, width, height, intrinsics, distortion);
  } catch (const Error& e) {
    // Point at the line of the offending field.
    const std::string what = e.what();
    YAML::Node at = node;
    if (what.rfind("model", 0) == 0) at = map.required("model");
    if (what.rfind("resolution", 0) == 0) at = resolution;
    if (what.rfind("intrinsics", 0) == 0) at = intrinsics_node;
    if (what.rfind("distortion", 0) == 0 && distortion_node.IsDefined()) at = distortion_node;
    throwAt(doc, at, path, what);
  }

  std::map<std::string, double> parameters;
  const YAML::Node params = map.optional("parameters");
  if (params.IsDefined()) {
    if (!params.IsMap()) throwAt(doc, params, map.join("parameters"), "expected a map of numbers");
    for (auto it = params.begin(); it != params.end(); ++it) {
      const std::string key = it->first.Scalar();
      const std::string p = map.join("parameters") + "." + key;
      if (key.empty()) throwAt(doc, it->first, p, "empty parameter name");
      if (!parameters.emplace(key, map.finiteAt(it->second, p)).second)
        throwAt(doc, it->first, p, "duplicate key");
    }
  }
  return CameraSensor{name, role, *camera, readRigidTransform(map, "T_B_C"), std::move(parameters)};
}

RangeFinderSensor readRangeFinder(const Document& doc, const YAML::Node& node) {
  const MapView map(doc, node, "range_finder",
                    {"T_B_L", "min_range_m", "max_range_m", "noise_sigma_m"});
  RangeFinderSensor rf;
  rf.T_B_L = readRigidTransform(map, "T_B_L");
  rf.min_range_m = map.nonNegative("min_range_m");
  rf.max_range_m = map.positive("max_range_m");
  if (!(rf.max_range_m > rf.min_range_m))
    throwAt(doc, map.required("max_range_m"), map.join("max_range_m"),
            "must be greater than min_range_m");
  rf.noise_sigma_m = map.nonNegative("noise_sigma_m");
  return rf;
}

// --- writing ----------------------------------------------------------------

/// The shortest text that reads back to the same double (std::to_chars), so
/// that 320 prints as "320" and 1/3 as "0.3333333333333333".
void emitDouble(YAML::Emitter& out, double v) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  if (ec != std::errc()) throw Error("sensors.yaml: cannot format a number");
  out << std::string(buf, end);
}

void emitMatrix(YAML::Emitter& out, const Mat4& T) {
  out << YAML::BeginSeq;
  for (int r = 0; r < 4; ++r) {
    out << YAML::Flow << YAML::BeginSeq;
    for (int c = 0; c < 4; ++c) emitDouble(out, T(r, c));
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq;
}

void emitNumbers(YAML::Emitter& out, const VecX& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < v.size(); ++i) emitDouble(out, v[i]);
  out << YAML::EndSeq;
}

void emitNumber(YAML::Emitter& out, const char* key, double v) {
  out << YAML::Key << key << YAML::Value;
  emitDouble(out, v);
}

}  // namespace

SensorRig parseSensorsYaml(const std::string& text, const std::string& name) {
  const Document doc = config::loadString(text, name);
  const MapView top(doc, doc.root, "",
                    {"cameras", "imu", "gravity_m_s2", "timeshift_cam_imu", "range_finder"});
  SensorRig rig;

  const YAML::Node cameras = top.required("cameras");
  if (!cameras.IsSequence() || cameras.size() == 0)
    throwAt(doc, cameras, "cameras", "expected a non-empty list of cameras");
  std::set<std::string> names;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    rig.cameras.push_back(readCamera(doc, cameras[i], indexed("cameras", i)));
    if (!names.insert(rig.cameras.back().name).second)
      throwAt(doc, cameras[i]["name"], indexed("cameras", i) + ".name",
              "duplicate camera name '" + rig.cameras.back().name + "'");
  }

  const MapView imu(doc, top.required("imu"), "imu",
                    {"accelerometer_noise_density", "accelerometer_random_walk",
                     "gyroscope_noise_density", "gyroscope_random_walk", "update_rate"});
  rig.imu.accelerometer_noise_density = imu.nonNegative("accelerometer_noise_density");
  rig.imu.accelerometer_random_walk = imu.nonNegative("accelerometer_random_walk");
  rig.imu.gyroscope_noise_density = imu.nonNegative("gyroscope_noise_density");
  rig.imu.gyroscope_random_walk = imu.nonNegative("gyroscope_random_walk");
  rig.imu.update_rate = imu.positive("update_rate");

  rig.gravity_m_s2 = top.positive("gravity_m_s2");

  const YAML::Node shift = top.optional("timeshift_cam_imu");
  if (shift.IsDefined()) {
    const double t_s = top.finiteAt(shift, "timeshift_cam_imu");
    if (!(std::abs(t_s) <= kMaxTimeshiftS))
      throwAt(doc, shift, "timeshift_cam_imu", "must be within ±1e5 s");
    rig.time_offset_cam_imu_ns = secondsToNs(t_s);
  }

  const YAML::Node rf = top.optional("range_finder");
  if (rf.IsDefined()) rig.range_finder = readRangeFinder(doc, rf);

  try {
    rig.validate();  // everything above was checked with lines; this is a safety net
  } catch (const Error& e) {
    throw Error::inFile(name, 0, e.what());
  }
  return rig;
}

SensorRig readSensorsYaml(const std::string& path) { return parseSensorsYaml(readFile(path), path); }

std::string formatSensorsYaml(const SensorRig& rig) {
  rig.validate();
  if (!(std::abs(nsToSeconds(rig.time_offset_cam_imu_ns)) <= kMaxTimeshiftS))
    throw Error("time_offset_cam_imu_ns: must be within ±1e5 s");
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const CameraSensor& c : rig.cameras) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << c.name;
    out << YAML::Key << "role" << YAML::Value << std::string(cameraRoleName(c.role));
    out << YAML::Key << "model" << YAML::Value << std::string(c.camera.model());
    out << YAML::Key << "resolution" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << c.camera.width() << c.camera.height() << YAML::EndSeq;
    out << YAML::Key << "intrinsics" << YAML::Value;
    emitNumbers(out, c.camera.intrinsics());
    out << YAML::Key << "distortion_coeffs" << YAML::Value;
    emitNumbers(out, c.camera.distortion());
    out << YAML::Key << "T_B_C" << YAML::Value;
    emitMatrix(out, c.T_B_C.matrix());
    out << YAML::Key << "parameters" << YAML::Value;
    if (c.parameters.empty()) {
      out << YAML::Flow << YAML::BeginMap << YAML::EndMap;
    } else {
      out << YAML::BeginMap;
      for (const auto& [key, value] : c.parameters) emitNumber(out, key.c_str(), value);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;

  out << YAML::Key << "imu" << YAML::Value << YAML::BeginMap;
  emitNumber(out, "accelerometer_noise_density", rig.imu.accelerometer_noise_density);
  emitNumber(out, "accelerometer_random_walk", rig.imu.accelerometer_random_walk);
  emitNumber(out, "gyroscope_noise_density", rig.imu.gyroscope_noise_density);
  emitNumber(out, "gyroscope_random_walk", rig.imu.gyroscope_random_walk);
  emitNumber(out, "update_rate", rig.imu.update_rate);
  out << YAML::EndMap;

  emitNumber(out, "gravity_m_s2", rig.gravity_m_s2);
  emitNumber(out, "timeshift_cam_imu", nsToSeconds(rig.time_offset_cam_imu_ns));

  if (rig.range_finder) {
    const RangeFinderSensor& rf = *rig.range_finder;
    out << YAML::Key << "range_finder" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "T_B_L" << YAML::Value;
    emitMatrix(out, rf.T_B_L.matrix());
    emitNumber(out, "min_range_m", rf.min_range_m);
    emitNumber(out, "max_range_m", rf.max_range_m);
    emitNumber(out, "noise_sigma_m", rf.noise_sigma_m);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  if (!out.good()) throw Error(std::string("sensors.yaml: YAML emitter error: ") + out.GetLastError());
  return "# evio sensor rig. SI units; T_B_C maps camera points into the body (IMU) frame;\n"
         "# IMU noise in Kalibr's names; timeshift_cam_imu in s (t_imu = t_cam + shift).\n" +
         std::string(out.c_str()) + "\n";
}

void writeSensorsYaml(const std::string& path, const SensorRig& rig) {
  writeFileAtomic(path, formatSensorsYaml(rig));
}

}  // namespace evio::io
