#!/usr/bin/python3
"""Plot a trajectory folder written by `evio trajectory` (or any sequence folder).

Usage: plot_trajectory.py FOLDER [-o OUTPUT.png]

Reads FOLDER/groundtruth.txt (TUM: t px py pz qx qy qz qw) and, when present,
FOLDER/imu.txt (t ax ay az gx gy gz). Writes FOLDER/trajectory.png (or OUTPUT)
with: position over time, attitude (roll/pitch/yaw, intrinsic z-y-x Euler
angles in degrees) over time, a top view (x-y), and the IMU's angular rate.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load_table(path, columns):
    """Rows of a whitespace table with '#' comments; exits with a clear message on bad input."""
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as e:
        sys.exit(f"plot_trajectory: cannot read {path}: {e}")
    if data.shape[0] == 0 or data.shape[1] != columns:
        sys.exit(f"plot_trajectory: {path}: expected {columns} columns, got {data.shape[1] if data.size else 0}")
    return data


def euler_zyx_deg(q):
    """Roll, pitch, yaw in degrees of Hamilton quaternions given as rows (x, y, z, w)."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.degrees(np.unwrap(roll)), np.degrees(pitch), np.degrees(np.unwrap(yaw))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder")
    parser.add_argument("-o", "--output", help="output PNG (default FOLDER/trajectory.png)")
    args = parser.parse_args()

    gt = load_table(os.path.join(args.folder, "groundtruth.txt"), 8)
    t = gt[:, 0] - gt[0, 0]
    p = gt[:, 1:4]
    roll, pitch, yaw = euler_zyx_deg(gt[:, 4:8])
    imu_path = os.path.join(args.folder, "imu.txt")
    imu = load_table(imu_path, 7) if os.path.exists(imu_path) else None

    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    ax = axes[0, 0]
    for i, name in enumerate("xyz"):
        ax.plot(t, p[:, i], label=name)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("position [m]")
    ax.set_title("position of the body in W")
    ax.legend()
    ax.grid(True, alpha=0.3)

    ax = axes[0, 1]
    ax.plot(t, roll, label="roll")
    ax.plot(t, pitch, label="pitch")
    ax.plot(t, yaw, label="yaw")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("angle [deg]")
    ax.set_title("attitude (z-y-x Euler angles)")
    ax.legend()
    ax.grid(True, alpha=0.3)

    ax = axes[1, 0]
    ax.plot(p[:, 0], p[:, 1], lw=0.8)
    ax.plot(p[0, 0], p[0, 1], "go", label="start")
    ax.plot(p[-1, 0], p[-1, 1], "rs", label="end")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("top view")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend()
    ax.grid(True, alpha=0.3)

    ax = axes[1, 1]
    if imu is not None:
        ti = imu[:, 0] - gt[0, 0]
        for i, name in enumerate("xyz"):
            ax.plot(ti, np.degrees(imu[:, 4 + i]), lw=0.5, label=f"$\\omega_{name}$")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("angular rate [deg/s]")
        ax.set_title("IMU gyroscope (imu.txt)")
        ax.legend()
        ax.grid(True, alpha=0.3)
    else:
        ax.axis("off")

    fig.suptitle(os.path.basename(os.path.normpath(args.folder)))
    fig.tight_layout()
    out = args.output or os.path.join(args.folder, "trajectory.png")
    fig.savefig(out, dpi=100)
    print(out)


if __name__ == "__main__":
    main()
