#!/usr/bin/python3
"""Real-time factor of the estimator pipelines (README "Real time (issue 22)").

    experiments/scripts/realtime_table.py --evio build/release/bin/evio \\
        --sequence poster_6dof=<folder> --sequence mars_yard_circle=<folder> \\
        [--repeats 3] [--methods eklt-vio,klt-vio,haste-vio] [--out out/realtime]

Runs `evio estimate <folder> --method M --init groundtruth --config
estimator/config/sim.yaml` for every sequence, method and thread setting
(frontend.threads 1 or 2, with or without backend_thread; KLT tracks on one
thread, so KLT-VIO runs with and without the backend thread), --repeats times
each, under /usr/bin/time -v, and prints Markdown tables of the medians:

  1. per run: wall-clock RTF (processing time / data time, summary.yaml
     total_s over the data span); the RTF the run would have on idle cores,
     from the CPU time per stage and the tracking's critical path (a lower
     bound: thread wake-ups not counted; see idle_rtf); CPU seconds (process,
     all threads); events per CPU second of the whole pipeline; peak resident
     memory;
  2. RTF against event rate: timing.txt (a line per 0.1 s of data, wall clock)
     of each run cut into windows, each window's event rate and RTF, the
     median RTF of the windows in each event-rate band (medians over the
     repeats' windows together).

The load average (`uptime`) before and after each run is printed too: the
machine is shared, so compare ratios measured in one sitting.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys

import yaml

CONFIGS = [  # (label, frontend.threads, backend_thread)
    ("1 thread", 1, False),
    ("2 tracker threads", 2, False),
    ("2 tracker threads + backend thread", 2, True),
]
RATE_BANDS_MEV = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 1e9]  # event-rate bands, M events/s


def load_average():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def read_summary(path):
    with open(path) as f:
        return yaml.safe_load(f)


def idle_rtf(summary, backend_thread, data_s):
    """Wall time the run would take on idle cores, from summary.yaml's CPU
    per stage (stage_cpu_s): the reading thread (reading, pre-filter, the
    tracking's critical path, synchroniser) and the backend side (backend,
    health, writer) one after the other, or side by side with the backend
    thread. Thread wake-ups and hand-overs are not counted: a lower bound."""
    c = summary["stage_cpu_s"]
    front = c["read_s"] + c["prefilter_s"] + c["tracking_critical_path_s"] + c["sync_s"]
    back = c["backend_s"] + c["output_s"]
    return (max(front, back) if backend_thread else front + back) / data_s


def read_timing(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            t, processing, events = line.split()[:3]  # a 4th column, features, since timing.txt gained it
            rows.append((float(t), float(processing), int(events)))
    return rows


def run_once(evio, config, folder, method, threads, backend_thread, out):
    cmd = ["/usr/bin/time", "-v", evio, "estimate", folder, "--method", method, "--init", "groundtruth",
           "--config", config, "-q", "-o", out, "--set", f"frontend.threads={threads}",
           "--set", f"backend_thread={'true' if backend_thread else 'false'}"]
    load_before = load_average()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{proc.stderr}")
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", proc.stderr).group(1))
    s = read_summary(os.path.join(out, "summary.yaml"))
    data_s = s["data_end_s"] - s["data_start_s"]
    times = s["stage_times_s"]
    events = s["counts"]["events"]
    return {
        "rtf": times["total_s"] / data_s,
        "rtf_idle": idle_rtf(s, backend_thread, data_s),
        "cpu_s": times["cpu_s"],
        "events": events,
        "ev_per_cpu_s": events / times["cpu_s"] if times["cpu_s"] > 0 else 0.0,
        "rss_mb": rss_kb / 1024.0,
        "load": (load_before, load_average()),
        "timing": read_timing(os.path.join(out, "timing.txt")),
    }


def window_rtfs(timing, window_s=0.2):
    """(event rate in M ev/s, RTF) of consecutive windows of about window_s."""
    out = []
    start = 0
    for k in range(1, len(timing)):
        dt = timing[k][0] - timing[start][0]
        if dt < window_s - 1e-9:
            continue
        dp = timing[k][1] - timing[start][1]
        de = timing[k][2] - timing[start][2]
        out.append((de / dt / 1e6, dp / dt))
        start = k
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--evio", required=True)
    ap.add_argument("--config", default=os.path.join(os.path.dirname(__file__), "..", "..", "estimator", "config",
                                                     "sim.yaml"))
    ap.add_argument("--sequence", action="append", required=True, help="name=folder")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--methods", default="eklt-vio,klt-vio,haste-vio")
    ap.add_argument("--out", default="out/realtime")
    args = ap.parse_args()

    rows = []
    bands = {}
    for spec in args.sequence:
        name, folder = spec.split("=", 1)
        for method in args.methods.split(","):
            configs = CONFIGS if method in ("eklt-vio", "haste-vio") else [c for c in CONFIGS if c[1] == 1] + [
                ("1 thread + backend thread", 1, True)]
            for label, threads, bt in configs:
                runs = []
                for r in range(args.repeats):
                    out = os.path.join(args.out, f"{name}_{method}_{threads}_{int(bt)}_{r}")
                    runs.append(run_once(args.evio, args.config, folder, method, threads, bt, out))
                    print(f"{name} {method} {label} run {r}: RTF {runs[-1]['rtf']:.3f}, CPU {runs[-1]['cpu_s']:.2f} s, "
                          f"load {runs[-1]['load'][0]:.1f}/{runs[-1]['load'][1]:.1f}", file=sys.stderr)
                med = lambda key: statistics.median(run[key] for run in runs)
                loads = [x for run in runs for x in run["load"]]
                rows.append((name, method, label, med("rtf"), min(run["rtf"] for run in runs), med("rtf_idle"), med("cpu_s"),
                             med("ev_per_cpu_s"), med("events"), med("rss_mb"), min(loads), max(loads)))
                windows = [w for run in runs for w in window_rtfs(run["timing"])]
                for lo, hi in zip(RATE_BANDS_MEV[:-1], RATE_BANDS_MEV[1:]):
                    sel = [rtf for rate, rtf in windows if lo <= rate < hi]
                    if sel:
                        bands.setdefault((method, label), {})[(name, lo, hi)] = (statistics.median(sel), len(sel))

    print("| sequence | method | threads | RTF wall median (min) | RTF idle cores (from CPU) | CPU s | events per CPU s "
          "| events | peak RSS MB | load |")
    print("|---|---|---|---|---|---:|---:|---:|---:|---|")
    for (name, method, label, rtf, rtf_min, rtf_idle, cpu, evs, events, rss, lo, hi) in rows:
        ev = f"{evs / 1e6:.2f} M" if events > 0 else "–"
        n = f"{events / 1e6:.2f} M" if events > 0 else "–"
        print(f"| {name} | {method} | {label} | {rtf:.2f} ({rtf_min:.2f}) | {rtf_idle:.2f} | {cpu:.2f} | {ev} | {n} | "
              f"{rss:.0f} | {lo:.1f}–{hi:.1f} |")
    print()
    print("| method | threads | sequence | event rate (M ev/s) | RTF median (windows of 0.2 s) |")
    print("|---|---|---|---|---|")
    for (method, label), per in bands.items():
        for (name, lo, hi), (rtf, n) in sorted(per.items()):
            band = f"{lo:g}–{hi:g}" if hi < 1e8 else f"≥ {lo:g}"
            print(f"| {method} | {label} | {name} | {band} | {rtf:.2f} ({n}) |")


if __name__ == "__main__":
    main()
