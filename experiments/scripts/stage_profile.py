#!/usr/bin/python3
"""Where EKLT-VIO's CPU goes, per stage, on a set of sequences (README
"Real time (issue 22)", the per-stage table of every campaign cell).

    experiments/scripts/stage_profile.py --evio build/release/bin/evio \\
        --sequence poster_6dof=<folder> [--sequence NAME=<folder>[,key=value...]] \\
        [--repeats 3] [--out out/stage_profile]

Runs `evio estimate <folder> --method eklt-vio --init groundtruth --config
estimator/config/sim.yaml` on one thread for every sequence, --repeats times,
with any key=value after the folder as `--set` overrides (e.g.
backend.slam_min_depth_m=5.0 for the Mars sequences whose ground is 10 m
below, as the campaigns run them). Prints one Markdown row per sequence from
the summary.yaml of the run with the median process CPU time: the data span,
the events, CPU seconds, CPU seconds per second of data, events per CPU
second, and each stage's share of the stages' CPU (stage_cpu_s: reading,
pre-filter, tracking with EKLT's own split into the optimisation, the event
lookups and the frames, synchroniser, backend, writing).
"""
import argparse
import os
import subprocess
import sys

import yaml

STAGES = ["read_s", "prefilter_s", "tracking_s", "sync_s", "backend_s", "output_s"]


def parse_sequence(text):
    """NAME=FOLDER[,key=value...] -> (name, folder, [key=value, ...])."""
    if "=" not in text:
        sys.exit(f"stage_profile: --sequence {text}: expected NAME=FOLDER")
    name, rest = text.split("=", 1)
    folder, *overrides = rest.split(",")
    if not os.path.isdir(folder):
        sys.exit(f"stage_profile: --sequence {name}: no folder {folder}")
    return name, folder, overrides


def run(evio, config, folder, overrides, out):
    cmd = [evio, "estimate", folder, "--method", "eklt-vio", "--init", "groundtruth",
           "--config", config, "-o", out, "-q", "--set", "frontend.threads=1", "--set", "backend_thread=false"]
    for o in overrides:
        cmd += ["--set", o]
    subprocess.run(cmd, check=True)
    with open(os.path.join(out, "summary.yaml")) as f:
        return yaml.safe_load(f)


def row(name, summary):
    st = summary["stage_cpu_s"]
    total = sum(st[k] for k in STAGES)
    cpu = summary["stage_times_s"]["cpu_s"]
    span = summary["data_end_s"] - summary["data_start_s"]
    events = summary["counts"]["events"]

    def share(x):
        return f"{100.0 * x / total:.0f} %"

    return (f"| {name} | {span:.0f} s | {events / 1e6:.1f} M | {cpu:.2f} | {cpu / span:.3f} | "
            f"{events / cpu / 1e6:.2f} | {share(st['read_s'])} | {share(st['prefilter_s'])} | "
            f"{share(st['tracking_s'])} ({share(st['eklt_optimisation_s'])}; {share(st['eklt_events_s'])}; "
            f"{share(st['eklt_frames_s'])}) | {share(st['sync_s'])} | {share(st['backend_s'])} | "
            f"{share(st['output_s'])} |")


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--evio", required=True)
    p.add_argument("--sequence", action="append", required=True, help="NAME=FOLDER[,key=value...]")
    p.add_argument("--config", default=os.path.join(root, "estimator", "config", "sim.yaml"))
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--out", default="out/stage_profile")
    a = p.parse_args()
    if a.repeats < 1:
        sys.exit("stage_profile: --repeats must be at least 1")
    with open("/proc/loadavg") as f:
        print(f"load before: {f.read().split()[0]}")
    print("| sequence | length | events | CPU s | CPU s per data s | M events / CPU s | reading | pre-filter | "
          "tracking (EKLT optimisation; events; frames) | sync | backend | writing |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|")
    for text in a.sequence:
        name, folder, overrides = parse_sequence(text)
        runs = [run(a.evio, a.config, folder, overrides, os.path.join(a.out, f"{name}.{r}"))
                for r in range(a.repeats)]
        runs.sort(key=lambda s: s["stage_times_s"]["cpu_s"])
        print(row(name, runs[len(runs) // 2]), flush=True)
    with open("/proc/loadavg") as f:
        print(f"load after: {f.read().split()[0]}")


if __name__ == "__main__":
    main()
