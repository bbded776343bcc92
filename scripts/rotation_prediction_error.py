#!/usr/bin/python3
"""How good a start the gyro's rotation-only prediction is, on exact tracks.

For every exact track point (<sequence>/truth/tracks.txt, `id t x y`, one per
groundtruth stamp) that the same track also has --dt seconds later, compares
  - the displacement without a prediction, |u(t + dt) − u(t)|, with
  - the residual after predicting u(t + dt) from the true rotation alone, as
    the trackers' gyro prediction does (the point taken as infinitely far):
      f = unproject(u(t)),  f' = R_E1_E0 f,  û = project(f'),  |u(t + dt) − û|
with R_E1_E0 from the true event-camera poses (groundtruth.txt, T_W_E) and
the camera of calib.txt (fx fy cx cy, radial-tangential k1 k2 p1 p2 k3).
Prints the medians and the share of steps on which the prediction is worse.

    scripts/rotation_prediction_error.py /tmp/sim/poster_6dof --dt 0.01
"""
import argparse
import sys

import numpy as np


def rotation_matrix(q):
    """Rotation matrix of the unit quaternion (x, y, z, w)."""
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def distort(xn, k):
    """Normalised (x, y) to distorted normalised coordinates (radial-tangential)."""
    k1, k2, p1, p2, k3 = k
    x, y = xn
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 ** 3
    return np.array([x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                     y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y])


def undistort(xd, k, iterations=30):
    """Inverse of distort by fixed-point iteration."""
    xn = xd.copy()
    for _ in range(iterations):
        xn = xn + (xd - distort(xn, k))
    return xn


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequence")
    parser.add_argument("--dt", type=float, default=0.01, help="step between the two track points, s")
    args = parser.parse_args()
    try:
        calib = np.loadtxt(f"{args.sequence}/calib.txt", ndmin=1)
        poses = np.loadtxt(f"{args.sequence}/groundtruth.txt", comments="#", ndmin=2)
        tracks = np.loadtxt(f"{args.sequence}/truth/tracks.txt", comments="#", ndmin=2)
    except OSError as e:
        print(f"rotation_prediction_error: {e}", file=sys.stderr)
        return 1
    if calib.size not in (4, 9) or poses.shape[1] != 8 or tracks.shape[1] != 4:
        print("rotation_prediction_error: expected calib.txt `fx fy cx cy [k1 k2 p1 p2 k3]`, "
              "groundtruth.txt `t px py pz qx qy qz qw`, truth/tracks.txt `id t x y`", file=sys.stderr)
        return 1
    fx, fy, cx, cy = calib[:4]
    k = calib[4:9] if calib.size == 9 else np.zeros(5)
    R_W_E = {round(t, 6): rotation_matrix(q) for t, q in zip(poses[:, 0], poses[:, 4:8])}
    points = {(int(i), round(t, 6)): np.array([x, y]) for i, t, x, y in tracks}
    plain, residual = [], []
    for (track, t), u0 in points.items():
        t1 = round(t + args.dt, 6)
        u1 = points.get((track, t1))
        if u1 is None or t not in R_W_E or t1 not in R_W_E:
            continue
        xn = undistort(np.array([(u0[0] - cx) / fx, (u0[1] - cy) / fy]), k)
        f = R_W_E[t1].T @ R_W_E[t] @ np.array([xn[0], xn[1], 1.0])  # R_E1_E0 f
        if f[2] <= 0:
            continue
        xd = distort(f[:2] / f[2], k)
        predicted = np.array([fx * xd[0] + cx, fy * xd[1] + cy])
        plain.append(np.linalg.norm(u1 - u0))
        residual.append(np.linalg.norm(u1 - predicted))
    if not plain:
        print(f"rotation_prediction_error: no track point has a partner {args.dt} s later", file=sys.stderr)
        return 1
    plain, residual = np.array(plain), np.array(residual)
    print("steps dt_s median_displacement_px median_after_prediction_px prediction_worse_share")
    print(f"{len(plain)} {args.dt:g} {np.median(plain):.3f} {np.median(residual):.3f} {np.mean(residual > plain):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
