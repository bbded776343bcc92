#include "evio/estimator/backend/still_prefix.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>

#include "evio/core/so3.h"
#include "evio/estimator/backend/static_initializer.h"

namespace evio::estimator {

namespace {

struct BlockMean {
  Vec3 gyro = Vec3::Zero(), acc = Vec3::Zero();
};

BlockMean blockMean(const ImuSamples& samples, std::size_t first, std::size_t count) {
  BlockMean m;
  for (std::size_t i = first; i < first + count; ++i) {
    m.gyro += samples[i].gyro_B;
    m.acc += samples[i].acc_B;
  }
  m.gyro /= static_cast<double>(count);
  m.acc /= static_cast<double>(count);
  return m;
}

}  // namespace

std::optional<StillPrefix> stillPrefix(const ImuSamples& samples, const ImuNoiseDensities& noise,
                                       const StillPrefixTest& test) {
  if (samples.size() < 4) return std::nullopt;
  const double f = medianRateHz(samples);
  if (!(f > 0.0)) return std::nullopt;
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(test.block_s * f)));
  const std::size_t blocks = samples.size() / n;
  if (blocks < 2) return std::nullopt;
  // σ_b of one block's mean, per axis.
  const double sigma_gyro = noise.gyroscope_noise_density * std::sqrt(f / static_cast<double>(n));
  const double sigma_acc = noise.accelerometer_noise_density * std::sqrt(f / static_cast<double>(n));
  BlockMean sum = blockMean(samples, 0, n);
  std::size_t still = 1;
  for (std::size_t k = 1; k < blocks; ++k, ++still) {
    const BlockMean m = blockMean(samples, k * n, n);
    const double kd = static_cast<double>(k);
    const double scale = test.threshold_sigma * std::sqrt(1.0 + 1.0 / kd);
    const double gyro_change = (m.gyro - sum.gyro / kd).cwiseAbs().maxCoeff();
    const double acc_change = (m.acc - sum.acc / kd).cwiseAbs().maxCoeff();
    if (!(gyro_change <= scale * sigma_gyro) || !(acc_change <= scale * sigma_acc)) break;
    sum.gyro += m.gyro;
    sum.acc += m.acc;
  }
  StillPrefix out;
  out.readings = still * n;
  out.every_block = still == blocks;
  if (nsToSeconds(samples[out.readings - 1].t_ns - samples.front().t_ns) < test.min_s) return std::nullopt;
  const double c2 = test.threshold_sigma * test.threshold_sigma / 3.0;
  out.gyro_allowance_variance = c2 * sigma_gyro * sigma_gyro;
  out.acc_allowance_variance = c2 * sigma_acc * sigma_acc;
  return out;
}

double ImageRotationRate::chi2() const {
  const Eigen::LDLT<Mat3> ldlt(covariance);
  return omega_C.dot(ldlt.solve(omega_C));
}

std::optional<ImageRotationRate> imageRotationRate(const std::vector<BearingObservation>& observations,
                                                   TimeNs t0_ns, TimeNs t1_ns, double sigma_bearing_rad,
                                                   int min_features, double min_span_s) {
  // Each feature's first and last observation inside [t0, t1].
  std::map<std::int64_t, std::pair<const BearingObservation*, const BearingObservation*>> ends;
  for (const BearingObservation& o : observations) {
    if (o.t_ns < t0_ns || o.t_ns > t1_ns) continue;
    auto [it, inserted] = ends.try_emplace(o.id, &o, &o);
    if (!inserted) {
      if (o.t_ns < it->second.first->t_ns) it->second.first = &o;
      if (o.t_ns >= it->second.second->t_ns) it->second.second = &o;
    }
  }
  int n = 0;
  Mat3 A = Mat3::Zero();
  Vec3 g = Vec3::Zero();
  for (const auto& [id, e] : ends) {
    const double dt = nsToSeconds(e.second->t_ns - e.first->t_ns);
    if (dt < min_span_s) continue;
    const Mat3 J = so3::hat(e.first->bearing) * dt;  // ∂(b_b − b_a)/∂ω
    A += J.transpose() * J;
    g += J.transpose() * (e.second->bearing - e.first->bearing);
    ++n;
  }
  if (n < std::max(min_features, 2)) return std::nullopt;
  const Eigen::LDLT<Mat3> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-9)) return std::nullopt;
  ImageRotationRate out;
  out.omega_C = ldlt.solve(g);
  out.covariance = 2.0 * sigma_bearing_rad * sigma_bearing_rad * ldlt.solve(Mat3::Identity());
  out.features = n;
  return out;
}

}  // namespace evio::estimator
