#!/usr/bin/python3
"""Peak memory and time of `evio export --format rosbag` and `evio import`
on a short and a ten times longer sequence (README, "ROS 1 bags").

Usage: /usr/bin/python3 experiments/scripts/bag_memory.py <evio> <scratch folder>
       [--seconds 2] [--rate 200000] [--repeats 3] [--compression none]

Each sequence is synthetic and seeded (numbers only, no scene): uniformly
random events at --rate events/s, 1 kHz IMU, 20 Hz 240 x 180 frames and
200 Hz ground truth. Each command runs --repeats times; the table gives the
median wall time, the median CPU time (user + system) and the largest peak
resident set size (GNU time's %M).
"""
import argparse
import os
import shutil
import statistics
import subprocess

import numpy as np
from PIL import Image


def write_sequence(folder, seconds, rate, seed):
    rng = np.random.default_rng(seed)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(os.path.join(folder, "images"))
    with open(os.path.join(folder, "calib.txt"), "w") as f:
        f.write("199.1 198.8 132.2 110.7 -0.37 0.15 -3e-04 -8e-04 0\n")
    n = int(seconds * rate)
    t0 = 1_000_000_000
    step = 1_000_000  # events written per block: the generator's memory stays flat too
    with open(os.path.join(folder, "events.txt"), "w") as f:
        done = 0
        while done < n:
            k = min(step, n - done)
            t = t0 + (np.arange(done, done + k, dtype=np.int64) * 10**9) // rate  # evenly spaced
            x = rng.integers(0, 240, k)
            y = rng.integers(0, 180, k)
            p = rng.integers(0, 2, k)
            f.write("".join("%d.%09d %d %d %d\n" % (a // 10**9, a % 10**9, b, c, d) for a, b, c, d in zip(t, x, y, p)))
            done += k
    with open(os.path.join(folder, "imu.txt"), "w") as f:
        for i in range(int(seconds * 1000)):
            t = t0 + i * 1_000_000
            a = rng.normal(0, 1, 6)
            f.write("%d.%09d %r %r %r %r %r %r\n" % (t // 10**9, t % 10**9, *a.tolist()))
    with open(os.path.join(folder, "groundtruth.txt"), "w") as f:
        for i in range(int(seconds * 200)):
            t = t0 + i * 5_000_000
            f.write("%d.%09d %r 0 1.5 0 0 0 1\n" % (t // 10**9, t % 10**9, 0.01 * i))
    with open(os.path.join(folder, "images.txt"), "w") as f:
        for i in range(int(seconds * 20)):
            t = t0 + i * 50_000_000
            name = "images/frame_%08d.png" % i
            Image.fromarray(rng.integers(0, 256, (180, 240), dtype=np.uint8)).save(os.path.join(folder, name))
            f.write("%d.%09d %s\n" % (t // 10**9, t % 10**9, name))
    return n


def measure(cmd):
    """(wall s, CPU s, peak RSS MiB) of one run, as GNU time reports them.

    Through /usr/bin/time rather than wait4() from here: Linux counts the
    resident size a child had before exec (a fork of this Python process,
    numpy and all) in its ru_maxrss."""
    r = subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", *cmd], stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise SystemExit("failed: %s\n%s" % (" ".join(cmd), r.stderr))
    wall, user, system, rss_kib = r.stderr.strip().splitlines()[-1].split()
    return float(wall), float(user) + float(system), int(rss_kib) / 1024.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("evio")
    ap.add_argument("scratch")
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--rate", type=int, default=200_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--compression", default="none", choices=["none", "bz2", "lz4"])
    args = ap.parse_args()
    print("| sequence | events | command | wall s (median) | CPU s (median) | peak RSS MiB | bag MB |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for factor in (1, 10):
        seconds = args.seconds * factor
        seq = os.path.join(args.scratch, "seq_%gs" % seconds)
        n = write_sequence(seq, seconds, args.rate, seed=21)
        bag = os.path.join(args.scratch, "seq_%gs.bag" % seconds)
        out = os.path.join(args.scratch, "imported_%gs" % seconds)
        for name, cmd in (("export", [args.evio, "export", seq, "--format", "rosbag", "--compression",
                                      args.compression, "-o", bag, "-q"]),
                          ("import", [args.evio, "import", bag, "-o", out, "-q"])):
            runs = [measure(cmd) for _ in range(args.repeats)]
            print("| %g s | %d | %s | %.2f | %.2f | %.1f | %.1f |" % (
                seconds, n, name, statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs),
                max(r[2] for r in runs), os.path.getsize(bag) / 1e6))


if __name__ == "__main__":
    main()
