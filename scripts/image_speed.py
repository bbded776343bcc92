#!/usr/bin/python3
"""Image speed over time from a simulated sequence's exact truth tracks.

Reads <sequence>/truth/tracks.txt (`id t x y`: the exact projection of world
points through the event camera at every groundtruth stamp) and prints, per
window of --window seconds, the median over tracks of |d(x, y)/dt| in px/s
(finite differences between consecutive stamps of the same track).

    scripts/image_speed.py /tmp/dvs/shapes_rotation --window 0.1
"""
import argparse
import sys

import numpy as np


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequence")
    parser.add_argument("--window", type=float, default=0.1, help="window length, s")
    args = parser.parse_args()
    path = f"{args.sequence}/truth/tracks.txt"
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except OSError as e:
        print(f"image_speed: {path}: {e}", file=sys.stderr)
        return 1
    if data.shape[0] < 2 or data.shape[1] != 4:
        print(f"image_speed: {path}: expected rows `id t x y`", file=sys.stderr)
        return 1
    order = np.lexsort((data[:, 1], data[:, 0]))
    d = data[order]
    same = d[1:, 0] == d[:-1, 0]
    dt = d[1:, 1] - d[:-1, 1]
    ok = same & (dt > 0)
    speed = np.hypot(d[1:, 2] - d[:-1, 2], d[1:, 3] - d[:-1, 3])[ok] / dt[ok]
    t_mid = 0.5 * (d[1:, 1] + d[:-1, 1])[ok]
    t0 = t_mid.min()
    print("window_start_s median_px_per_s p90_px_per_s samples")
    k = 0
    while t0 + k * args.window <= t_mid.max():
        sel = (t_mid >= t0 + k * args.window) & (t_mid < t0 + (k + 1) * args.window)
        if sel.any():
            s = speed[sel]
            print(f"{k * args.window:.2f} {np.median(s):.1f} {np.percentile(s, 90):.1f} {sel.sum()}")
        k += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
