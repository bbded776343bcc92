#!/usr/bin/python3
"""Plots of a campaign's results, for `evio report`.

Usage: campaign_report.py RESULTS REPORT_DIR GROUPS_CSV

Reads RESULTS/summary.csv (one row per job), the per-job series
RESULTS/jobs/<id>/metrics_poses.csv (t_s, distance_m, gt_x.., es_x..,
position_m, rotation_deg, yaw_deg, gravity_deg, nees_*) and
RESULTS/jobs/<id>/metrics_rtf.csv (t_s, rtf, event_rate_hz, and features,
rtf_per_feature when the estimate's timing.txt has the features column), and GROUPS_CSV
(written by `evio report`: the ANEES bounds per group). Writes into
REPORT_DIR:
  box_mpe.png, box_ate.png, box_mye.png  Monte Carlo box plots per scenario and method (successful runs)
  success.png                            ok / diverged / failed per scenario and method
  error_vs_distance.png, error_vs_time.png  position error of every run, median per method
  trajectories_<scenario>.png            top view (x-y) of the aligned estimates against ground truth
  nees.png                               average NEES over the runs against time, with 95 % chi-square bounds
  rtf_vs_event_rate.png                  real-time factor of 0.2 s intervals against the event rate
  rtf_per_feature_vs_event_rate.png      the same RTF divided by the features tracked in each interval
                                         (the EKLT-VIO paper's Fig. 6b; jobs without the column left out)
and plots.txt: one line per figure, "wrote NAME" or "skipped NAME: reason".
"""

import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

lines = []


def note(text):
    lines.append(text)
    print(f"campaign_report: {text}")


def number(text):
    try:
        v = float(text)
        return v if math.isfinite(v) else None
    except (TypeError, ValueError):
        return None


def variant(row):
    """The group of a run within its scenario: (method, sweep)."""
    return (row["method"], row["sweep"])


def variant_key(v):
    """Sort key of a variant, as the C++ report orders its tables: the method
    as text, then the sweep key by key, numeric values by value, then the text."""
    method, sweep = v
    items = []
    for kv in sweep.split(";") if sweep else []:
        key, _, value = kv.partition("=")
        num = number(value)
        items.append((key, 0, num, "") if num is not None else (key, 1, 0.0, value))
    return (method, items, sweep)


def label(v, newline=True):
    """Short text for a variant: the method and the sweep values (keys in sweep_keys())."""
    method, sweep = v
    values = ",".join(kv.split("=", 1)[-1] for kv in sweep.split(";")) if sweep else ""
    return method + (("\n" if newline else " ") + values if values else "")


def sweep_keys(rows):
    keys = [kv.split("=", 1)[0] for kv in rows[0]["sweep"].split(";")] if rows and rows[0]["sweep"] else []
    return ", ".join(keys)


def load_series(path):
    if not os.path.isfile(path):
        return None
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        cols = {k: [] for k in reader.fieldnames}
        for r in reader:
            for k in cols:
                cols[k].append(number(r[k]))
    return {k: np.array([np.nan if v is None else v for v in vals]) for k, vals in cols.items()}


def save(fig, out, name):
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=110)
    plt.close(fig)
    note(f"wrote {name}")


def box_plot(rows, scenarios, out, key, ylabel, name):
    ok = [r for r in rows if r["status"] == "ok" and number(r.get(key)) is not None]
    if not ok:
        note(f"skipped {name}: no successful run has {key}")
        return
    fig, axes = plt.subplots(1, len(scenarios), figsize=(4.5 * len(scenarios), 4), squeeze=False)
    for ax, sc in zip(axes[0], scenarios):
        variants = sorted({variant(r) for r in rows if r["scenario"] == sc}, key=variant_key)
        data = [[number(r[key]) for r in ok if r["scenario"] == sc and variant(r) == v] for v in variants]
        present = [(v, d) for v, d in zip(variants, data) if d]
        if present:
            ax.boxplot([d for _, d in present], labels=[label(v) for v, _ in present], showmeans=True)
        ax.set_title(sc)
        if sweep_keys(rows):
            ax.set_xlabel(f"method, {sweep_keys(rows)}", fontsize=8)
        ax.set_ylabel(ylabel)
        ax.tick_params(axis="x", labelsize=7)
        ax.grid(alpha=0.3)
    save(fig, out, name)


def success_plot(rows, scenarios, out):
    fig, axes = plt.subplots(1, len(scenarios), figsize=(4.5 * len(scenarios), 4), squeeze=False)
    for ax, sc in zip(axes[0], scenarios):
        variants = sorted({variant(r) for r in rows if r["scenario"] == sc}, key=variant_key)
        bottom = np.zeros(len(variants))
        for status, colour in (("ok", "tab:green"), ("diverged", "tab:orange"), ("failed", "tab:red")):
            counts = np.array([sum(1 for r in rows if r["scenario"] == sc and variant(r) == v and
                                   r["done"] == "1" and r["status"] == status) for v in variants], float)
            ax.bar(range(len(variants)), counts, bottom=bottom, color=colour, label=status)
            bottom += counts
        ax.set_xticks(range(len(variants)), [label(v) for v in variants], fontsize=7)
        if sweep_keys(rows):
            ax.set_xlabel(f"method, {sweep_keys(rows)}", fontsize=8)
        ax.set_ylabel("runs")
        ax.set_title(sc)
        ax.legend(fontsize=7)
    save(fig, out, "success.png")


def error_plots(rows, scenarios, results, out):
    series = {}
    for r in rows:
        if r["done"] == "1" and r["status"] != "failed":
            s = load_series(os.path.join(results, "jobs", r["job_id"], "metrics_poses.csv"))
            if s is not None and len(s["t_s"]) > 0:
                series[r["job_id"]] = s
    if not series:
        for name in ("error_vs_distance.png", "error_vs_time.png", "trajectories.png"):
            note(f"skipped {name}: no job has metrics_poses.csv")
        return series
    for axis, xlabel, name in (("distance_m", "distance travelled [m]", "error_vs_distance.png"),
                               ("t_s", "time [s]", "error_vs_time.png")):
        fig, axes = plt.subplots(1, len(scenarios), figsize=(4.5 * len(scenarios), 4), squeeze=False)
        for ax, sc in zip(axes[0], scenarios):
            variants = sorted({variant(r) for r in rows if r["scenario"] == sc}, key=variant_key)
            for i, v in enumerate(variants):
                colour = f"C{i}"
                runs = [series[r["job_id"]] for r in rows
                        if r["scenario"] == sc and variant(r) == v and r["job_id"] in series]
                for s in runs:
                    ax.plot(s[axis], s["position_m"], color=colour, alpha=0.25, lw=0.7)
                if runs:
                    hi = min(np.nanmax(s[axis]) for s in runs)
                    lo = max(np.nanmin(s[axis]) for s in runs)
                    if hi > lo:
                        grid = np.linspace(lo, hi, 200)
                        med = np.nanmedian([np.interp(grid, s[axis], s["position_m"]) for s in runs], axis=0)
                        ax.plot(grid, med, color=colour, lw=2, label=label(v, newline=False))
            ax.set_title(sc)
            ax.set_xlabel(xlabel)
            ax.set_ylabel("position error [m]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=6)
        save(fig, out, name)
    for sc in scenarios:
        fig, ax = plt.subplots(figsize=(5.5, 5))
        drawn_gt = False
        variants = sorted({variant(r) for r in rows if r["scenario"] == sc}, key=variant_key)
        for i, v in enumerate(variants):
            runs = sorted((r for r in rows if r["scenario"] == sc and variant(r) == v and r["job_id"] in series),
                          key=lambda r: int(r["seed"]))
            if not runs:
                continue
            s = series[runs[0]["job_id"]]
            if not drawn_gt:
                ax.plot(s["gt_x"], s["gt_y"], "k-", lw=2, label=f"ground truth (seed {runs[0]['seed']})")
                drawn_gt = True
            ax.plot(s["es_x"], s["es_y"], color=f"C{i}", lw=1, label=f"{label(v, newline=False)} (seed {runs[0]['seed']})")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(f"{sc}: top view, aligned estimates")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
        save(fig, out, f"trajectories_{sc}.png")
    return series


def nees_plot(rows, scenarios, series, groups, out):
    with_nees = {k: s for k, s in series.items() if "nees_pose" in s and np.isfinite(s["nees_pose"]).any()}
    if not with_nees:
        note("skipped nees.png: no job has pose covariances (trajectory_covariance.txt)")
        return
    fig, axes = plt.subplots(1, len(scenarios), figsize=(4.5 * len(scenarios), 4), squeeze=False)
    for ax, sc in zip(axes[0], scenarios):
        variants = sorted({variant(r) for r in rows if r["scenario"] == sc}, key=variant_key)
        for i, v in enumerate(variants):
            runs = [with_nees[r["job_id"]] for r in rows
                    if r["scenario"] == sc and variant(r) == v and r["job_id"] in with_nees]
            if not runs:
                continue
            # Average over runs on a 0.1 s grid (each run's sample nearest to the grid time).
            t0 = max(np.nanmin(s["t_s"]) for s in runs)
            t1 = min(np.nanmax(s["t_s"]) for s in runs)
            if t1 <= t0:
                continue
            grid = np.arange(t0, t1, 0.1)
            per_run = []
            for s in runs:
                ok = np.isfinite(s["nees_pose"])
                t, n = s["t_s"][ok], s["nees_pose"][ok]
                idx = np.clip(np.searchsorted(t, grid), 1, len(t) - 1)
                near = np.where(np.abs(t[idx - 1] - grid) < np.abs(t[idx] - grid), idx - 1, idx)
                per_run.append(n[near])
            anees = np.mean(per_run, axis=0)
            ax.plot(grid, anees, color=f"C{i}", lw=1, label=f"{label(v, newline=False)} ({len(runs)} runs)")
            key = (sc, v[0], v[1])
            if key in groups:
                lo, hi = groups[key]
                ax.axhline(lo, color=f"C{i}", ls="--", lw=0.8)
                ax.axhline(hi, color=f"C{i}", ls="--", lw=0.8)
        ax.axhline(6.0, color="k", lw=0.5)
        ax.set_yscale("log")
        ax.set_title(sc)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("average NEES (6 dof); dashed: 95 % bounds")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    save(fig, out, "nees.png")


def rtf_scatter(rows, results, out, column, name, ylabel, missing):
    """Scatter of metrics_rtf.csv's `column` against the event rate, one colour
    per method, on a logarithmic y axis (RTF spans 0.1 to 100 across methods
    and machines, per feature three decades lower); non-positive and empty
    values left out."""
    fig, ax = plt.subplots(figsize=(6, 4.5))
    methods = sorted({r["method"] for r in rows})
    any_drawn = False
    for i, m in enumerate(methods):
        xs, ys = [], []
        for r in rows:
            if r["method"] != m or r["done"] != "1":
                continue
            s = load_series(os.path.join(results, "jobs", r["job_id"], "metrics_rtf.csv"))
            if s is not None and column in s and len(s[column]) > 0:
                xs.append(s["event_rate_hz"])
                ys.append(s[column])
        if xs:
            x, y = np.concatenate(xs), np.concatenate(ys)
            keep = np.isfinite(y) & (y > 0)
            if keep.any():
                ax.scatter(x[keep], y[keep], s=4, alpha=0.4, color=f"C{i}", label=m)
                any_drawn = True
    if not any_drawn:
        plt.close(fig)
        note(f"skipped {name}: {missing}")
        return
    if column == "rtf":
        ax.axhline(1.0, color="k", lw=0.8, ls="--")
    ax.set_yscale("log")
    ax.set_xlabel("event rate [events/s]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    save(fig, out, name)


def rtf_plot(rows, results, out):
    rtf_scatter(rows, results, out, "rtf", "rtf_vs_event_rate.png", "real-time factor (0.2 s intervals)",
                "no job has a positive real-time factor (timing.txt → metrics_rtf.csv)")
    rtf_scatter(rows, results, out, "rtf_per_feature", "rtf_per_feature_vs_event_rate.png",
                "real-time factor per tracked feature (0.2 s intervals)",
                "no job has an RTF per feature (timing.txt without its features column → metrics_rtf.csv)")


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    results, out, groups_csv = sys.argv[1:4]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(results, "summary.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    groups = {}
    if os.path.isfile(groups_csv):
        with open(groups_csv, newline="") as f:
            for g in csv.DictReader(f):
                lo, hi = number(g["anees_lower_95"]), number(g["anees_upper_95"])
                if lo is not None and hi is not None:
                    groups[(g["scenario"], g["method"], g["sweep"])] = (lo, hi)
    scenarios = list(dict.fromkeys(r["scenario"] for r in rows))
    if not rows:
        note("skipped all plots: summary.csv has no jobs")
    else:
        box_plot(rows, scenarios, out, "paper.mpe_percent", "MPE [%]", "box_mpe.png")
        box_plot(rows, scenarios, out, "ate.position_m.rmse", "ATE RMSE [m]", "box_ate.png")
        box_plot(rows, scenarios, out, "paper.mye_deg_per_m", "MYE [deg/m]", "box_mye.png")
        success_plot(rows, scenarios, out)
        series = error_plots(rows, scenarios, results, out)
        nees_plot(rows, scenarios, series, groups, out)
        rtf_plot(rows, results, out)
    with open(os.path.join(out, "plots.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
