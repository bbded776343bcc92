#!/usr/bin/python3
"""Statistics of feature-track errors against their truth: how large, how
they grow with the track's age, and how long they stay correlated.

Input: a tracks file (`evio track`, id t x y, pixels) and the true positions
of the same tracks written by `evio evaluate-tracks ... --truth-output` from
that file (id t x y, the truth of each point until its truth ends). A track
point is paired with the truth point of the same id and the same time
stamp, which holds because the truth file copies the tracks' stamps; points
without one are skipped. Each track's error is e(t) = tracked − true, px, and
its age the time since the track's first point with a truth. Printed:

  * points, RMS error per axis, median |e|;
  * per age bin: RMS |e|, median |e| and the robust per-axis variance
    (1.4826 · median absolute deviation)²;
  * the drift rate q (px² per s, per axis): the least-squares slope of the
    robust variance (mean of the two axes) against the bins' mean age,
    weighted by the square root of each bin's point count, with its
    intercept the variance at the start;
  * the normalised error correlation at lags L, not mean-removed (a bias
    shared by every point counts as correlation):
      c(L) = Σ e(t)·e(t+L) / sqrt(Σ |e(t)|² Σ |e(t+L)|²)
    over all tracks and points whose track still has a point at t + L
    (e(t+L) linearly interpolated between the track's points; at lags
    shorter than the track's point spacing c(L) mostly compares a point with
    itself);
  * the same for the error's change since the track's first kept point,
    e(t) − e(t0), which is what a filter that took the first point as the
    feature's bearing sees;
  * the integrated correlation time T = ∫ c(L) dL, by the trapezoid rule
    over the given lags from c(0) = 1 up to the first lag where c turns
    negative (there linearly to its zero): a run of samples Δt apart whose
    errors correlate so carries about as much information about a slowly
    changing quantity as one sample per 2T (for Δt ≪ T). With
    --equivalent-at τ also the σ a filter that weighs the samples with an
    exponential correlation of time constant τ (κ = coth(Δt/2τ) ≈ 2τ/Δt)
    must state to take in the same information: σ_τ = σ sqrt(T/τ), σ the RMS
    error per axis.

  * the tails: the share of points with |e| beyond 1, 2 and 3 px, and the
    runs of consecutive points of one track beyond --off-px (a track that
    sits on a wrong alignment for a while, not a single bad point): how many
    runs last --off-run points or more, and how many points they hold.

Points whose error exceeds --max-error (px) are left out of every figure
but the point count: gross losses, which the filter's gate rejects, would
otherwise set the RMS and the correlations. The correlation interpolates
across the gaps they leave.

With --common-bin W the errors shared by the features at one time are
measured: time is cut into bins of W s, each feature's errors in a bin are
averaged, and for every bin with at least --common-min-features features the
mean over the features m (px) and the spread s² of the features around it
(per axis, divisor n − 1) are taken. Printed: the mean over the bins of
|m|²/2 (the per-axis variance of the all-feature mean), the same expected if
the features' errors were independent (mean of s²/n), and their ratio. A
ratio well above 1 is an error common to the features (a shared shift of
the image) that averaging over features cannot remove. With
--common-lags k1,k2,... (bins) also the shared part's covariance k bins
apart: the mean over bin pairs of m_b·m_{b+k}/2 less the features' own
part, n_c C / (n_b n_{b+k}) with C = Σ_f d_f,b·d_f,b+k / (2 (n_c − 1))
over the n_c features in both bins, d the feature's deviation from its
bin's mean; and that over the shared variance at lag 0 (the difference of
the first two figures above).

With --lag-model the tracker's along-motion lag a + τ|v| is fitted and
added back along v̂ at every point first (as track_noise_stats.py does, v the
central difference of the true positions): what remains is the error the
filter meets, since it compensates that lag (docs/algorithms.md "Tracker
lag"). With --frames images.txt as well, the points stamped at a frame's
time (to the nanosecond: EKLT's detections and bootstraps, measured on the
frames) do not lag: they are left out of the fit and left as they are, as
the synchroniser leaves them. (An event point is stamped at the middle of
its batch; one that fell on a frame's nanosecond would be taken for a frame
point too.)

Usage: track_error_stats.py TRACKS TRUTH [--lags 0.01,0.1,0.4,0.8]
       [--age-bins 0,0.1,0.4,1.6,100] [--max-error 5] [--skip-s 0]
       [--off-px 2] [--off-run 10] [--lag-model] [--min-speed 50] [--frames images.txt]
       [--common-bin 0.01] [--common-min-features 8] [--common-lags 1,2,5,10]
       [--equivalent-at 0.042]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from track_noise_stats import remove_lag  # noqa: E402  (the lag fit the noise figures use)


def read_points(path):
    """{id: (t[], xy[n,2])} from an `id t x y` file (comments '#')."""
    rows = np.loadtxt(path, comments="#", ndmin=2)
    tracks = {}
    for fid in np.unique(rows[:, 0]).astype(int):
        r = rows[rows[:, 0] == fid]
        order = np.argsort(r[:, 1], kind="stable")
        tracks[fid] = (r[order, 1], r[order, 2:4])
    return tracks


def true_velocity(t, xy):
    """px/s at each truth point: central differences, one-sided at the ends."""
    if len(t) < 2:
        return np.zeros_like(xy)
    return np.stack([np.gradient(xy[:, 0], t), np.gradient(xy[:, 1], t)], axis=1)


def errors(tracks, truth, skip_s):
    """{id: (t[], e[n,2], age[n], v[n,2])}: tracked − true at the truth's
    times, and the true image velocity there."""
    out = {}
    for fid, (tt, xy_true) in truth.items():
        if fid not in tracks:
            continue
        t, xy = tracks[fid]
        keep = np.isin(t, tt)
        t_k, xy_k = t[keep], xy[keep]
        truth_at = {ti: xi for ti, xi in zip(tt, xy_true)}
        v_true = true_velocity(tt, xy_true)
        velocity_at = {ti: vi for ti, vi in zip(tt, v_true)}
        e = np.array([xy_k[i] - truth_at[ti] for i, ti in enumerate(t_k)]).reshape(-1, 2)
        v = np.array([velocity_at[ti] for ti in t_k]).reshape(-1, 2)
        if len(t_k) < 2:
            continue
        sel = t_k >= skip_s
        out[fid] = (t_k[sel], e[sel], (t_k - t_k[0])[sel], v[sel])
    return out


def correlation(errs, lag, since_start):
    num, a2, b2, n = 0.0, 0.0, 0.0, 0
    for t, e, *_ in errs.values():
        if len(t) < 2:
            continue
        ee = e - e[0] if since_start else e
        later = t + lag
        ok = later <= t[-1]
        if not ok.any():
            continue
        ex = np.interp(later[ok], t, ee[:, 0])
        ey = np.interp(later[ok], t, ee[:, 1])
        num += float(np.sum(ee[ok, 0] * ex + ee[ok, 1] * ey))
        a2 += float(np.sum(ee[ok] ** 2))
        b2 += float(np.sum(ex ** 2 + ey ** 2))
        n += int(ok.sum())
    return (num / np.sqrt(a2 * b2) if a2 > 0 and b2 > 0 else float("nan")), n


def off_runs(errs, off_px):
    """Lengths (points) of the runs of consecutive points of one track with
    |e| > off_px."""
    runs = []
    for _, e, *_ in errs.values():
        length = 0
        for off in np.linalg.norm(e, axis=1) > off_px:
            if off:
                length += 1
            elif length:
                runs.append(length)
                length = 0
        if length:
            runs.append(length)
    return np.array(runs, dtype=int)


def integrated_time(lags, corr):
    """(T in s, how it ended: "zero", "lags" or "no pairs"): the trapezoid
    over (0, 1), (L_i, c_i) up to the first zero crossing, the last lag, or
    the first lag without pairs, whichever comes first."""
    total, t0, c0 = 0.0, 0.0, 1.0
    for t1, c1 in sorted(zip(lags, corr)):
        if not np.isfinite(c1):
            return total, "no pairs"
        if c1 < 0.0:
            t_zero = t0 + (t1 - t0) * c0 / (c0 - c1)
            return total + 0.5 * c0 * (t_zero - t0), "zero"
        total += 0.5 * (c0 + c1) * (t1 - t0)
        t0, c0 = t1, c1
    return total, "lags"


def bin_means(errs, bin_s):
    """{bin: {feature: its mean error in the bin (px, [2])}}."""
    per_bin = {}
    for fid, (t, e, *_) in errs.items():
        if len(t) == 0:
            continue
        bins = np.floor(t / bin_s).astype(np.int64)
        for b in np.unique(bins):
            per_bin.setdefault(int(b), {})[fid] = e[bins == b].mean(axis=0)
    return per_bin


def shared_covariance(errs, bin_s, min_features, lag_bins):
    """(pairs, covariance px² per axis) of the error the features share,
    lag_bins bins apart (see the module comment)."""
    per_bin = {b: f for b, f in bin_means(errs, bin_s).items() if len(f) >= min_features}
    means = {b: np.mean(list(f.values()), axis=0) for b, f in per_bin.items()}
    total, pairs = 0.0, 0
    for b, feats in per_bin.items():
        later = per_bin.get(b + lag_bins)
        if later is None:
            continue
        both = feats.keys() & later.keys()
        if len(both) == 1:
            continue  # one feature in both bins: its own part cannot be told from the shared
        # The features' own covariance, from their deviations from the bin
        # means (divisor n_c − 1, as the spread's), enters the means' product
        # n_c times over n_b n_{b+k} (none without a feature in both).
        own = 0.0
        if both:
            products = [float(np.dot(feats[f] - means[b], later[f] - means[b + lag_bins])) for f in both]
            own = sum(products) / (len(both) - 1) * len(both) / (len(feats) * len(later))
        total += 0.5 * float(np.dot(means[b], means[b + lag_bins])) - 0.5 * own
        pairs += 1
    return pairs, (total / pairs if pairs else float("nan"))


def common_mode(errs, bin_s, min_features):
    """(bins used, median features per bin, mean |m|²/2, mean s²/n): the
    per-axis variance of the bins' all-feature mean error and what it would
    be with independent errors (see the module comment)."""
    common, independent, sizes = [], [], []
    for b, feats in sorted(bin_means(errs, bin_s).items()):
        feature_means = np.array(list(feats.values()))
        n = len(feature_means)
        if n < min_features:
            continue
        m = feature_means.mean(axis=0)
        spread = np.sum((feature_means - m) ** 2) / (2 * (n - 1))  # per axis
        common.append(float(np.dot(m, m)) / 2)
        independent.append(spread / n)
        sizes.append(n)
    if not common:
        return 0, 0, float("nan"), float("nan")
    return len(common), float(np.median(sizes)), float(np.mean(common)), float(np.mean(independent))


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tracks")
    ap.add_argument("truth")
    ap.add_argument("--lags", default="0.01,0.04,0.1,0.2,0.4,0.8,1.6")
    ap.add_argument("--age-bins", default="0,0.1,0.2,0.4,0.8,1.6,3.2,100")
    ap.add_argument("--skip-s", type=float, default=0.0, help="ignore points before this time, s")
    ap.add_argument("--max-error", type=float, default=5.0, help="leave out points with |e| above this, px")
    ap.add_argument("--off-px", type=float, default=2.0, help="a point is off beyond this |e|, px")
    ap.add_argument("--off-run", type=int, default=10, help="count runs of at least this many off points")
    ap.add_argument("--lag-model", action="store_true", help="remove the fitted along-motion lag a + tau |v| first")
    ap.add_argument("--min-speed", type=float, default=50.0, help="px/s: the lag fit's points (as track_lag.py)")
    ap.add_argument("--frames", default="", help="with --lag-model: the sequence's images.txt; points at its "
                    "times were measured on frames and carry no lag")
    ap.add_argument("--common-bin", type=float, default=0.0, help="s: measure the error common to the features (0: off)")
    ap.add_argument("--common-min-features", type=int, default=8, help="bins with fewer features are left out")
    ap.add_argument("--common-lags", default="", help="bins: the shared part's covariance this many bins apart")
    ap.add_argument("--equivalent-at", type=float, default=0.0,
                    help="s: the sigma an exponential weighting of this time constant must state (0: not printed)")
    a = ap.parse_args()
    if a.common_lags.strip() and not a.common_bin > 0:
        sys.exit("track_error_stats: --common-lags needs --common-bin")
    if a.common_min_features < 2:
        sys.exit("track_error_stats: --common-min-features must be at least 2 (a spread needs two features)")
    if a.frames and not a.lag_model:
        sys.exit("track_error_stats: --frames needs --lag-model")
    return a


def frame_times_ns(images_txt):
    """The frames' times, integer ns, from an images.txt (`t path` lines)."""
    times = []
    with open(images_txt) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                times.append(round(float(line.split()[0]) * 1e9))
    return np.array(times, dtype=np.int64)


def without_lag(errs, min_speed, frames_ns):
    """errs with the fitted along-motion lag added back at every point that
    lags, those not stamped at a frame's time (printed)."""
    ids = list(errs)
    sizes = [len(errs[fid][0]) for fid in ids]
    t_all = np.concatenate([errs[fid][0] for fid in ids])
    lagging = ~np.isin(np.round(t_all * 1e9).astype(np.int64), frames_ns)
    e_all = np.concatenate([errs[fid][1] for fid in ids])
    v_all = np.concatenate([errs[fid][3] for fid in ids])
    e_compensated, lag_a, lag_tau = remove_lag(e_all[lagging], v_all[lagging], min_speed)
    e_all[lagging] = e_compensated
    if not lagging.all():
        print(f"points measured on frames, left as they are: {int((~lagging).sum())}")
    out = {}
    for fid, part in zip(ids, np.split(e_all, np.cumsum(sizes)[:-1])):
        t, _, age, v = errs[fid]
        out[fid] = (t, part, age, v)
    print(f"lag removed: a = {lag_a:.3f} px, tau = {lag_tau * 1e3:.2f} ms")
    return out


def print_age_bins(e, age, edges):
    """Per age bin: RMS and median |e|, robust variance; then the drift fit."""
    print("age bin (s)      points  RMS |e| (px)  median |e| (px)  robust var x, y (px²)")
    mean_age, var, weight = [], [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (age >= lo) & (age < hi)
        if m.sum() >= 20:
            norm = np.linalg.norm(e[m], axis=1)
            robust_sigma = 1.4826 * np.median(np.abs(e[m] - np.median(e[m], axis=0)), axis=0)
            print(f"[{lo:5.2f}, {hi:6.2f})  {int(m.sum()):8d}  {np.sqrt(np.mean(norm ** 2)):12.3f}  "
                  f"{np.median(norm):15.3f}  {robust_sigma[0] ** 2:8.3f} {robust_sigma[1] ** 2:8.3f}")
            mean_age.append(float(np.mean(age[m])))
            var.append(float(np.mean(robust_sigma ** 2)))
            weight.append(float(m.sum()))
    if len(var) >= 2:
        w = np.sqrt(np.array(weight))
        A = np.stack([np.ones(len(var)), np.array(mean_age)], axis=1)
        (v0, q), *_ = np.linalg.lstsq(A * w[:, None], np.array(var) * w, rcond=None)
        print(f"per-axis variance ≈ {v0:.3f} px² + {q:.3f} px²/s · age")


def print_tails(errs, e, off_px, off_run):
    norm = np.linalg.norm(e, axis=1)
    print("points beyond 1 / 2 / 3 px: " + " / ".join(f"{100 * np.mean(norm > x):.1f} %" for x in (1, 2, 3)))
    runs = off_runs(errs, off_px)
    long_runs = runs[runs >= off_run]
    print(f"runs beyond {off_px:g} px: {len(runs)}; {len(long_runs)} of at least {off_run} points, "
          f"holding {int(long_runs.sum())} points")


def print_correlations(errs, e, lags, equivalent_at):
    """c(L) at the lags, the integrated time T and, with equivalent_at > 0, σ sqrt(T/τ)."""
    print("lag (s)  corr e(t)   pairs    corr e(t)-e(t0)")
    corr = []
    for lag in lags:
        c, n = correlation(errs, lag, False)
        c0, _ = correlation(errs, lag, True)
        corr.append(c)
        print(f"{lag:7.3f}  {c:9.3f}  {n:8d}  {c0:9.3f}")
    T, end = integrated_time(lags, corr)
    print(f"integrated correlation time {T * 1e3:.1f} ms " +
          {"zero": "(to its first zero)", "lags": f"(no zero within the lags, to {max(lags) * 1e3:g} ms)",
           "no pairs": "(to the last lag with pairs)"}[end])
    if equivalent_at > 0:
        sigma = np.sqrt(np.mean(e ** 2))
        print(f"sigma to state with an exponential weighting of {equivalent_at * 1e3:g} ms: "
              f"{sigma * np.sqrt(T / equivalent_at):.2f} px (RMS {sigma:.3f} px per axis)")


def print_common(errs, bin_s, min_features, lag_bins):
    """The shared part: its variance against independent errors, then k bins apart."""
    bins, features, common, independent = common_mode(errs, bin_s, min_features)
    print(f"common to the features, bins of {bin_s * 1e3:g} ms: {bins} bins, {features:g} features per bin; "
          f"all-feature mean {common:.4f} px² per axis, {independent:.4f} if independent, "
          f"ratio {common / independent:.2f}")
    shared0 = common - independent
    for k in lag_bins:
        pairs, cov = shared_covariance(errs, bin_s, min_features, k)
        corr_text = f"correlation {cov / shared0:.2f}" if shared0 > 0 else "no shared variance at lag 0"
        print(f"shared part {k} bins ({k * bin_s * 1e3:g} ms) apart: {pairs} pairs, covariance "
              f"{cov:.4f} px² per axis, {corr_text}")


def main():
    a = parse_args()
    errs = errors(read_points(a.tracks), read_points(a.truth), a.skip_s)
    if not errs:
        sys.exit("no track has a truth")
    n_all = sum(len(v[0]) for v in errs.values())
    for fid, (t, e, age, v) in list(errs.items()):
        keep = np.linalg.norm(e, axis=1) <= a.max_error
        errs[fid] = (t[keep], e[keep], age[keep], v[keep])
    if a.lag_model:
        frames = frame_times_ns(a.frames) if a.frames else np.array([], dtype=np.int64)
        errs = without_lag(errs, a.min_speed, frames)
    e = np.concatenate([v[1] for v in errs.values()])
    age = np.concatenate([v[2] for v in errs.values()])
    print(f"tracks {len(errs)}  points {n_all}, {len(e)} with |e| <= {a.max_error} px")
    print(f"RMS error x {np.sqrt(np.mean(e[:, 0] ** 2)):.3f} px  y {np.sqrt(np.mean(e[:, 1] ** 2)):.3f} px  "
          f"median |e| {np.median(np.linalg.norm(e, axis=1)):.3f} px")
    print_age_bins(e, age, [float(x) for x in a.age_bins.split(",")])
    print_tails(errs, e, a.off_px, a.off_run)
    print_correlations(errs, e, [float(x) for x in a.lags.split(",")], a.equivalent_at)
    if a.common_bin > 0:
        print_common(errs, a.common_bin, a.common_min_features,
                     [int(x) for x in a.common_lags.split(",") if x.strip()])


if __name__ == "__main__":
    main()
