#!/usr/bin/python3
"""Plot the statistics of a sequence written by `evio stats -o stats.json`.

Usage: stats.py STATS.json OUTPUT.png

Panels: event rate over time (events/s per rate window, with p50 and p90),
the frames' brightness histogram (fraction of pixels per DN, log scale,
256 bins), and the key figures as text. Either half is left out when the
sequence has no events or no frames.
"""

import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: stats.py STATS.json OUTPUT.png")
    with open(sys.argv[1]) as f:
        stats = json.load(f)
    ev, fr = stats.get("events"), stats.get("frames")
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    ax_rate, ax_hist, ax_text = axes
    if ev:
        w = ev["rate_window_s"]
        series = ev["rate_series_hz"]
        ax_rate.step([i * w for i in range(len(series))], series, where="post", lw=0.8)
        for key, style in (("p50", "--"), ("p90", ":")):
            ax_rate.axhline(ev["rate_hz"][key], ls=style, color="k", lw=0.8, label=key)
        ax_rate.set(xlabel="time since first event [s]", ylabel=f"events/s ({w * 1e3:g} ms windows)",
                    title="event rate")
        ax_rate.legend()
    else:
        ax_rate.set_axis_off()
    if fr and fr["count"]:
        h = fr["histogram"]
        total = float(sum(h))
        ax_hist.bar(range(256), [c / total for c in h], width=1.0)
        ax_hist.set_yscale("log")
        ax_hist.set(xlabel="DN", ylabel="fraction of pixels", title="frame brightness (all frames)", xlim=(-1, 256))
    else:
        ax_hist.set_axis_off()
    lines = [stats["folder"], f"sensor {stats['width']}x{stats['height']}"]
    if ev:
        lines += [
            f"events {ev['count']}  ON fraction {ev['on_fraction']:.3f}",
            f"interval min/p1/p5/p50 [ms] {ev['interval_s']['min'] * 1e3:.2f} / {ev['interval_s']['p1'] * 1e3:.2f}"
            f" / {ev['interval_s']['p5'] * 1e3:.2f} / {ev['interval_s']['p50'] * 1e3:.2f}",
            f"under 1 ms {ev['interval_under_1ms_fraction']:.4f}",
            f"events/burst p50/p90 {ev['events_per_burst']['p50']:g} / {ev['events_per_burst']['p90']:g}",
            f"isolated {ev['isolated_rate_hz_per_pixel']:.3g} Hz/px",
        ]
    if fr and fr["count"]:
        exposure = "unknown" if fr["exposure_s"] is None else f"{fr['exposure_s'] * 1e3:.3f} ms"
        lines += [
            f"frames {fr['count']} at {fr['rate_hz']:.2f} Hz, exposure {exposure}",
            f"mean {fr['brightness_mean_dn']:.1f} DN, at 0 {fr['fraction_at_0']:.3f}, at 255 {fr['fraction_at_255']:.3f}",
            f"frame max p50 {fr['max_dn']['p50']:g} DN, at max {fr['fraction_at_max']:.3f}",
            f"white level p50 {fr['white_level_dn']['p50']:g} DN, within 10 DN {fr['fraction_near_white']:.3f}",
            f"Laplacian variance {fr['laplacian_variance_dn2']:.1f} DN^2",
        ]
    ax_text.set_axis_off()
    ax_text.text(0, 1, "\n".join(lines), va="top", family="monospace", fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
