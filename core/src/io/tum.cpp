#include "evio/core/io/tum.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace evio::io {

namespace {

const std::vector<std::string> kPoseColumns = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};

std::vector<std::string> covarianceColumns() {
  std::vector<std::string> c = kPoseColumns;
  for (const char* n : {"Pr11", "Pr12", "Pr13", "Pr22", "Pr23", "Pr33", "Pt11", "Pt12", "Pt13",
                        "Pt22", "Pt23", "Pt33"})
    c.emplace_back(n);
  return c;
}

Pose poseFromRow(const TimedTableReader& table, const double* v) {
  const Quat q(v[6], v[3], v[4], v[5]);  // Eigen order w x y z
  const double norm = q.norm();
  if (!(std::fabs(norm - 1.0) <= 0.01))
    table.fail("qx qy qz qw", "quaternion norm " + std::to_string(norm) + " is not 1 (within 1 %)");
  return Pose(q, Vec3(v[0], v[1], v[2]));  // Pose normalises
}

void poseToRow(const Pose& pose, double* v) {
  const Vec3& p = pose.translation();
  const Quat& q = pose.quaternion();
  v[0] = p.x();
  v[1] = p.y();
  v[2] = p.z();
  v[3] = q.x();
  v[4] = q.y();
  v[5] = q.z();
  v[6] = q.w();
}

Mat3 upperToSymmetric(const double* u) {
  Mat3 m;
  m << u[0], u[1], u[2],  //
      u[1], u[3], u[4],   //
      u[2], u[4], u[5];
  return m;
}

void symmetricToUpper(const Mat3& m, double* u) {
  u[0] = m(0, 0);
  u[1] = m(0, 1);
  u[2] = m(0, 2);
  u[3] = m(1, 1);
  u[4] = m(1, 2);
  u[5] = m(2, 2);
}

void requirePsd(const TimedTableReader& table, const Mat3& m, const char* what) {
  const Eigen::SelfAdjointEigenSolver<Mat3> es(m, Eigen::EigenvaluesOnly);
  const double tol = 1e-12 * std::max(1.0, m.trace());
  if (es.eigenvalues().minCoeff() < -tol)
    table.fail(what, "covariance is not positive semi-definite");
}

}  // namespace

TumReader::TumReader(std::string path) : table_(std::move(path), kPoseColumns, "TUM trajectory") {}

bool TumReader::next(StampedPose& pose) {
  double v[7];
  if (!table_.next(&pose.t_ns, v)) return false;
  pose.pose = poseFromRow(table_, v);
  return true;
}

Trajectory readTum(const std::string& path) {
  TumReader reader(path);
  Trajectory out;
  StampedPose p;
  while (reader.next(p)) out.push_back(p);
  return out;
}

TumWriter::TumWriter(std::string path, const std::vector<std::string>& header)
    : table_(std::move(path), header) {}

void TumWriter::append(const StampedPose& pose) {
  double v[7];
  poseToRow(pose.pose, v);
  table_.append(pose.t_ns, v, 7);
}

void TumWriter::close() { table_.close(); }

void writeTum(const std::string& path, const Trajectory& trajectory,
              const std::vector<std::string>& header) {
  TumWriter w(path, header);
  for (const auto& p : trajectory) w.append(p);
  w.close();
}

std::vector<StampedPoseCovariance> readTumCovariance(const std::string& path) {
  TimedTableReader table(path, covarianceColumns(), "TUM trajectory with covariance");
  std::vector<StampedPoseCovariance> out;
  StampedPoseCovariance row;
  double v[19];
  while (table.next(&row.t_ns, v)) {
    row.pose = poseFromRow(table, v);
    row.cov_orientation = upperToSymmetric(v + 7);
    row.cov_position = upperToSymmetric(v + 13);
    requirePsd(table, row.cov_orientation, "Pr");
    requirePsd(table, row.cov_position, "Pt");
    out.push_back(row);
  }
  return out;
}

void writeTumCovariance(const std::string& path, const std::vector<StampedPoseCovariance>& poses,
                        const std::vector<std::string>& header) {
  TimedTableWriter w(path, header);
  double v[19];
  for (const auto& p : poses) {
    poseToRow(p.pose, v);
    symmetricToUpper(p.cov_orientation, v + 7);
    symmetricToUpper(p.cov_position, v + 13);
    w.append(p.t_ns, v, 19);
  }
  w.close();
}

}  // namespace evio::io
