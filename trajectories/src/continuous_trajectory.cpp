#include "evio/trajectories/continuous_trajectory.h"

#include "evio/core/error.h"
#include "evio/trajectories/taylor_rotation.h"

namespace evio {

ContinuousTrajectory::ContinuousTrajectory(TimeNs start_ns, TimeNs end_ns)
    : start_ns_(start_ns), end_ns_(end_ns) {
  require(end_ns > start_ns, "trajectory: end time must be after start time");
}

TrajectoryState ContinuousTrajectory::evaluate(TimeNs t_ns) const {
  if (t_ns < start_ns_ || t_ns > end_ns_)
    throw Error("trajectory: time " + std::to_string(nsToSeconds(t_ns)) + " s is outside [" +
                std::to_string(nsToSeconds(start_ns_)) + ", " + std::to_string(nsToSeconds(end_ns_)) +
                "] s");
  const Motion m = motion(nsToSeconds(t_ns - start_ns_));
  TrajectoryState s;
  s.t_ns = t_ns;
  s.T_W_B = Pose(m.R_W_B.c[0], m.p_W.c[0]);
  s.v_W = m.p_W.derivative(1);
  s.a_W = m.p_W.derivative(2);
  s.omega_B = taylor::angularVelocityBody(m.R_W_B);
  s.alpha_B = taylor::angularAccelerationBody(m.R_W_B);
  return s;
}

}  // namespace evio
