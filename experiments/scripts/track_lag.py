#!/usr/bin/python3
"""Along-motion lag of feature tracks against their true positions.

    experiments/scripts/track_lag.py <tracks.txt> <truth.txt> [--min-speed 50]

<tracks.txt> is an `evio track` output (id t x y, pixels of one camera);
<truth.txt> the same tracks' true positions written by
`evio evaluate-tracks ... --truth-output <truth.txt>` (same ids and stamps,
until each track's truth ends).

For every sample k of a track with a true position p_k at t_k, the true image
velocity v_k is the central difference (p_{k+1} - p_{k-1}) / (t_{k+1} - t_{k-1})
of the true positions; the along-motion lag is

    lag_px = -(x_k - p_k) . v_k / |v_k|     (px, > 0: the track trails the truth)
    lag_s  = lag_px / |v_k|                 (s: the latency that explains it)

Samples slower than --min-speed px/s (direction ill-defined) and the first
sample of each track (the detection, exact by construction) are skipped.
Prints the medians overall and per speed band, and the least-squares fit of

    lag_px = a + tau |v|                    (a px in distance, tau s in time)

over the samples whose error is below --max-error px (lost tracks left out):
the model that `sync.track_lag_px = a` and `sync.track_latency_s = tau`
compensate (estimator/frontend/synchronizer.h).
"""
import argparse
import os
import statistics
import sys
from collections import defaultdict

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plots"))
from plot_tracks import load_tracks  # noqa: E402  (the project's reader of `id t x y` files)


def read(path):
    """Track id -> [(t, x, y), ...] in file order."""
    tracks = defaultdict(list)
    for i, t, x, y in load_tracks(path):
        tracks[int(i)].append((t, x, y))
    return tracks


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracks")
    ap.add_argument("truth")
    ap.add_argument("--min-speed", type=float, default=50.0, help="px/s")
    ap.add_argument("--max-error", type=float, default=5.0, help="px: samples farther off are left out of the fit")
    a = ap.parse_args()
    est, truth = read(a.tracks), read(a.truth)
    lags = []  # (speed px/s, lag px, lag s)
    for i, tr in truth.items():
        e = {round(t, 9): (x, y) for t, x, y in est.get(i, [])}
        for k in range(1, len(tr) - 1):
            t0, x0, y0 = tr[k - 1]
            t, x, y = tr[k]
            t1, x1, y1 = tr[k + 1]
            if t1 <= t0 or round(t, 9) not in e:
                continue
            vx, vy = (x1 - x0) / (t1 - t0), (y1 - y0) / (t1 - t0)
            speed = (vx * vx + vy * vy) ** 0.5
            if speed < a.min_speed:
                continue
            ex, ey = e[round(t, 9)]
            lag_px = -((ex - x) * vx + (ey - y) * vy) / speed
            lags.append((speed, lag_px, lag_px / speed, ((ex - x) ** 2 + (ey - y) ** 2) ** 0.5))
    if not lags:
        sys.exit("no samples faster than --min-speed with a true position")
    print(f"samples {len(lags)}: median lag {statistics.median(l[1] for l in lags):.3f} px, "
          f"median latency {1e3 * statistics.median(l[2] for l in lags):.2f} ms")
    bands = [(50, 100), (100, 200), (200, 300), (300, 400), (400, 1e9)]
    for lo, hi in bands:
        sel = [l for l in lags if lo <= l[0] < hi]
        if len(sel) < 20:
            continue
        print(f"  {lo:>4.0f}-{hi if hi < 1e9 else float('inf'):>4.0f} px/s: n {len(sel):6d}, "
              f"lag {statistics.median(l[1] for l in sel):.3f} px, "
              f"latency {1e3 * statistics.median(l[2] for l in sel):.2f} ms")
    fit = [l for l in lags if l[3] <= a.max_error]
    if len(fit) >= 2:
        a_px, tau_s = fitLag(fit)
        rms = (sum(l[1] ** 2 for l in fit) / len(fit)) ** 0.5
        rms_fit = (sum((l[1] - a_px - tau_s * l[0]) ** 2 for l in fit) / len(fit)) ** 0.5
        print(f"fit over {len(fit)} samples within {a.max_error:g} px: lag = a + tau |v| with "
              f"a = {a_px:.3f} px, tau = {1e3 * tau_s:.2f} ms; along-motion rms {rms:.3f} px -> {rms_fit:.3f} px")


def fitLag(samples):
    """Least squares of lag_px = a + tau * speed: the 2 x 2 normal equations."""
    n = len(samples)
    s1 = sum(l[0] for l in samples)
    s2 = sum(l[0] * l[0] for l in samples)
    r1 = sum(l[1] for l in samples)
    r2 = sum(l[0] * l[1] for l in samples)
    det = n * s2 - s1 * s1
    if det <= 0.0:
        return r1 / n, 0.0
    return (s2 * r1 - s1 * r2) / det, (n * r2 - s1 * r1) / det


if __name__ == "__main__":
    main()
