#!/usr/bin/python3
"""How well a tracker's stated noise describes its real error, band by band
of its quality.

Input: a tracks file and its noise sidecar from `evio track --noise`
(TRACKS and TRACKS.noise.txt: id t quality cov_xx cov_xy cov_yy, px²), and
the same tracks' true positions from `evio evaluate-tracks ... --truth-output`
(id t x y). Points are joined on (id, t). Left out: points without a truth or
without a stated covariance; the first and last truth point of each track
(the first is the detection, exact by construction; the velocity below needs
a neighbour on both sides); points with |e| above --max-error px (gross
losses).

The error is e = tracked − true, px. The filter compensates the tracker's
lag along the motion (a + τ|v|, docs/consistency.md "Tracker lag"), so with
--lag-model the lag is fitted as experiments/scripts/track_lag.py fits it
(lag = −e·v̂ against the true image speed |v|, least squares over the points
faster than --min-speed px/s) and a + τ|v| is added back along v̂ of every
point before any figure (v: the central difference of the true positions).
Printed, over all points and per quality band (points below the first band
edge count only in the first line):

  * points; share with |e| beyond 2 px;
  * the error's mean square per axis, (ex² + ey²)/2, px²;
  * the mean stated variance per axis, (cov_xx + cov_yy)/2, px²;
  * the mean NEES per degree of freedom, eᵀ Σ⁻¹ e / 2, which is 1 when the
    stated covariance is the error's;

and two least-squares fits of the bands' mean squares against their mean
cost (2 (1 − quality)), each band weighted by its point count:
ms ≈ v0 + k · cost and ms ≈ v0 + k · cost².

Usage: track_noise_stats.py TRACKS TRUTH [--bands 0.6,0.7,0.8,0.85,0.9,0.95,1.0001]
       [--max-error 5] [--lag-model] [--min-speed 50]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plots"))
from plot_tracks import load_table, load_tracks  # noqa: E402  (the project's readers of whitespace tables)
from track_lag import fitLag  # noqa: E402  (the lag model's fit, as the tracker-lag figures use it)


def keyed(rows):
    """{(id, t rounded to the ns): row}."""
    return {(int(r[0]), round(r[1] * 1e9)): r for r in rows}


def joined(tracks_path, truth_path):
    """Arrays of the joined points: e[n,2], v[n,2] (true image velocity,
    px/s), quality[n], cov[n,2,2]."""
    tracks = keyed(load_tracks(tracks_path))
    noise = keyed(load_table(tracks_path + ".noise.txt", "id t quality cov_xx cov_xy cov_yy"))
    truth_rows = load_tracks(truth_path)
    e, v, q, cov = [], [], [], []
    for fid in np.unique(truth_rows[:, 0]).astype(int):
        g = truth_rows[truth_rows[:, 0] == fid]
        g = g[np.argsort(g[:, 1], kind="stable")]
        for k in range(1, len(g) - 1):  # k = 0: the detection; central differences need both neighbours
            key = (fid, round(g[k, 1] * 1e9))
            if key not in tracks or key not in noise:
                continue
            c = noise[key][3:6]
            if c[0] <= 0 or c[2] <= 0:
                continue
            e.append(tracks[key][2:4] - g[k, 2:4])
            v.append((g[k + 1, 2:4] - g[k - 1, 2:4]) / (g[k + 1, 1] - g[k - 1, 1]))
            q.append(noise[key][2])
            cov.append([[c[0], c[1]], [c[1], c[2]]])
    return np.array(e).reshape(-1, 2), np.array(v).reshape(-1, 2), np.array(q), np.array(cov).reshape(-1, 2, 2)


def remove_lag(e, v, min_speed):
    """e with the fitted lag a + τ|v| added back along the motion; (a, τ).
    The fit takes the points faster than min_speed px/s, as track_lag.py."""
    speed = np.linalg.norm(v, axis=1)
    moving = speed > 0.0
    u = np.zeros_like(v)
    u[moving] = v[moving] / speed[moving, None]
    lag = -np.sum(e * u, axis=1)
    fast = speed >= min_speed
    if fast.sum() < 2:
        sys.exit(f"{os.path.basename(sys.argv[0])}: fewer than two points faster than {min_speed:g} px/s to fit the lag")
    a, tau = fitLag(list(zip(speed[fast], lag[fast])))
    return e + ((a + tau * speed) * moving)[:, None] * u, a, tau


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tracks")
    ap.add_argument("truth")
    ap.add_argument("--bands", default="0.6,0.7,0.8,0.85,0.9,0.95,1.0001", help="quality band edges")
    ap.add_argument("--max-error", type=float, default=5.0, help="leave out points with |e| above this, px")
    ap.add_argument("--lag-model", action="store_true", help="remove the fitted along-motion lag a + tau |v| first")
    ap.add_argument("--min-speed", type=float, default=50.0, help="px/s: the lag fit's points (as track_lag.py)")
    a = ap.parse_args()
    e, v, q, cov = joined(a.tracks, a.truth)
    keep = np.linalg.norm(e, axis=1) <= a.max_error
    e, v, q, cov = e[keep], v[keep], q[keep], cov[keep]
    if len(e) == 0:
        sys.exit("no point has both a truth and a stated covariance")
    if a.lag_model:
        e, lag_a, lag_tau = remove_lag(e, v, a.min_speed)
        print(f"lag removed: a = {lag_a:.3f} px, tau = {lag_tau * 1e3:.2f} ms")
    nees = np.einsum("ni,nij,nj->n", e, np.linalg.inv(cov), e) / 2
    print(f"points {len(e)}; mean square per axis {np.mean(e ** 2):.3f} px², "
          f"stated {np.mean((cov[:, 0, 0] + cov[:, 1, 1]) / 2):.3f} px², NEES per dof {np.mean(nees):.2f}")
    print("quality band     points  beyond 2 px  mean square  stated  NEES/dof   (px² per axis)")
    edges = [float(x) for x in a.bands.split(",")]
    cost, ms, weight = [], [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (q >= lo) & (q < hi)
        if m.sum() < 20:
            continue
        band_ms = float(np.mean(e[m] ** 2))
        stated = float(np.mean((cov[m, 0, 0] + cov[m, 1, 1]) / 2))
        print(f"[{lo:.2f}, {min(hi, 1):.2f}{')' if hi <= 1 else ']'}  {int(m.sum()):8d}  {100 * np.mean(np.linalg.norm(e[m], axis=1) > 2):9.1f} %"
              f"  {band_ms:11.3f}  {stated:6.3f}  {np.mean(nees[m]):8.2f}")
        cost.append(float(np.mean(2 * (1 - q[m]))))
        ms.append(band_ms)
        weight.append(float(m.sum()))
    if len(ms) >= 2:
        w = np.sqrt(np.array(weight))  # rows scaled by √n: each band weighs by its point count
        for name, x in (("cost", np.array(cost)), ("cost²", np.array(cost) ** 2)):
            A = np.stack([np.ones(len(ms)), x], axis=1)
            (v0, k), *_ = np.linalg.lstsq(A * w[:, None], np.array(ms) * w, rcond=None)
            rms = np.sqrt(np.average((A @ [v0, k] - np.array(ms)) ** 2, weights=weight))
            print(f"mean square per axis ≈ {v0:.3f} px² + {k:.3f} px² · {name}  (weighted rms misfit {rms:.3f} px²)")


if __name__ == "__main__":
    main()
