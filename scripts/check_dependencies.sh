#!/usr/bin/env bash
# Checks the module arrows of docs/architecture.md#dependency-direction on the
# sources (the CMake target links enforce them at link time; this catches an
# include of a system header such as <embree3/...> or <OpenEXR/...> that would
# compile anyway):
#   estimator never includes the simulator side, Embree, OpenEXR or GDAL;
#   core, trajectories, scenes and the simulator never include the estimator;
#   core includes no other evio module;
#   ROS headers appear only in bags/ (which uses core only) and the apps;
#   inside the estimator, the backend and the frontend never include each
#   other (nor the pipeline that wires them), and the measurement contract
#   includes nothing of the estimator: both stand on it.
# Usage: scripts/check_dependencies.sh [source tree]   (default: this repository)
set -u
cd "${1:-$(dirname "$0")/..}" || exit 2
status=0
check() {  # check <what> <folders> <regex>
  local hits
  hits=$(grep -rnE "$3" $2 --include='*.h' --include='*.cpp' 2>/dev/null || true)
  if [ -n "$hits" ]; then
    echo "dependency violation: $1"
    echo "$hits"
    status=1
  fi
}
check "estimator includes simulator-side code" "estimator" \
  '#include *[<"](embree3/|OpenEXR/|Imf|gdal|evio/(simulator|scenes|trajectories|experiments)/|evio/core/io/(exr_file|raster_file|image_file)\.h)'
check "a lower module includes the estimator or experiments" "core trajectories scenes simulator" \
  '#include *[<"]evio/(estimator|experiments)/'
check "core includes another evio module" "core" \
  '#include *[<"]evio/(trajectories|scenes|simulator)/'
check "a module below the apps includes ROS or the bags module" "core trajectories scenes simulator estimator experiments/src experiments/include" \
  '#include *[<"](rosbag/|ros/|sensor_msgs/|geometry_msgs/|std_msgs/|evio/bags/)'
check "the bags module includes a module other than core" "bags" \
  '#include *[<"]evio/(trajectories|scenes|simulator|estimator|experiments)/'
check "trajectories includes scenes or the simulator" "trajectories" \
  '#include *[<"]evio/(scenes|simulator)/'
check "the backend includes the frontend or the pipeline" "estimator/backend" \
  '#include *[<"]evio/estimator/(frontend|pipeline)/'
check "the frontend includes the backend or the pipeline" "estimator/frontend" \
  '#include *[<"]evio/estimator/(backend|pipeline)/'
check "the measurement contract includes an estimator module" "estimator/contract" \
  '#include *[<"]evio/estimator/(frontend|backend|pipeline)/'
[ $status -eq 0 ] && echo "dependency arrows respected"
exit $status
