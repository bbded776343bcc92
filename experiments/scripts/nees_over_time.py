#!/usr/bin/python3
"""When a filter's NEES grows: the mean position and orientation NEES per
interval of data time, over the runs of each (scenario, method) of a campaign.

    experiments/scripts/nees_over_time.py <campaign folder> [--bin-s 1]
        [--end-s 12] [--scenarios a,b] [--methods m,n]

Reads every job's `metrics_poses.csv` (`evio evaluate` per-pose output: t_s
from the sequence start, nees_position and nees_orientation, 3 dof each; empty
or NaN where the pose has no covariance). A job folder is named
<scenario>.<method>.s<seed>.<hash> (`evio campaign`). For each pair and each
bin [k·bin, (k+1)·bin) prints

    mean NEES_position / mean NEES_orientation    (3 and 3 for a consistent filter)

over all poses of all its runs in that bin; "-" where none. The mean is not
robust: one diverging run sets it, which is the point (ANEES is a mean too).
"""
import argparse
import csv
import glob
import math
import os
import sys
from collections import defaultdict


def job_key(folder):
    """(scenario, method) of a job folder <scenario>.<method>.s<seed>.<hash>."""
    parts = os.path.basename(folder).split(".")
    if len(parts) < 4 or not parts[-2].startswith("s"):
        return None
    return parts[0], ".".join(parts[1:-2])


def add_job(path, bin_s, sums):
    """Adds the job's per-pose NEES to sums[bin] = [Σ position, Σ orientation, count]."""
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            try:
                t = float(row["t_s"])
                p = float(row["nees_position"])
                o = float(row["nees_orientation"])
            except (KeyError, ValueError):
                continue
            if math.isnan(p) or math.isnan(o):
                continue
            s = sums[int(t // bin_s)]
            s[0] += p
            s[1] += o
            s[2] += 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("campaign", help="campaign output folder (with jobs/)")
    ap.add_argument("--bin-s", type=float, default=1.0, help="interval length, s")
    ap.add_argument("--end-s", type=float, default=12.0, help="last interval ends here, s")
    ap.add_argument("--scenarios", default="", help="comma-separated scenario names (default: all)")
    ap.add_argument("--methods", default="", help="comma-separated method names (default: all)")
    a = ap.parse_args()
    if a.bin_s <= 0 or a.end_s <= 0:
        sys.exit("nees_over_time.py: --bin-s and --end-s must be > 0")
    jobs = os.path.join(a.campaign, "jobs")
    if not os.path.isdir(jobs):
        sys.exit(f"nees_over_time.py: {a.campaign}: no jobs/ folder (not a campaign output)")
    want_s = set(filter(None, a.scenarios.split(",")))
    want_m = set(filter(None, a.methods.split(",")))
    groups = defaultdict(lambda: defaultdict(lambda: [0.0, 0.0, 0]))
    runs = defaultdict(int)
    for folder in sorted(glob.glob(os.path.join(jobs, "*"))):
        key = job_key(folder)
        path = os.path.join(folder, "metrics_poses.csv")
        if key is None or not os.path.exists(path):
            continue
        if (want_s and key[0] not in want_s) or (want_m and key[1] not in want_m):
            continue
        add_job(path, a.bin_s, groups[key])
        runs[key] += 1
    bins = int(math.ceil(a.end_s / a.bin_s))
    print("scenario method runs | " + " | ".join(f"{k * a.bin_s:g}-{(k + 1) * a.bin_s:g} s" for k in range(bins)))
    for key in sorted(groups):
        cells = []
        for k in range(bins):
            p, o, n = groups[key][k]
            cells.append(f"{p / n:.1f} / {o / n:.1f}" if n else "-")
        print(f"{key[0]} {key[1]} {runs[key]} | " + " | ".join(cells))


if __name__ == "__main__":
    main()
