#!/usr/bin/python3
"""experiments/scripts/track_error_stats.py's tails on hand-made tracks whose
errors are known exactly: the shares of points beyond 1, 2 and 3 px and the
runs of consecutive points of one track beyond --off-px, counted per track
(a run never joins two tracks) with the points past --max-error left out;
the along-motion lag a + τ|v| that --lag-model fits and removes; the error
common to the features at one time (--common-bin) and how long that shared
part stays correlated (--common-lags); and the integrated correlation time
with the σ an exponential weighting must state for it (--equivalent-at)."""
import re
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "experiments", "scripts", "track_error_stats.py")


def write(path, rows):
    with open(path, "w") as f:
        f.write("# id t x y\n")
        for fid, t, x, y in rows:
            f.write(f"{fid} {t:.3f} {x} {y}\n")


def run(tracks, truth, *args):
    return subprocess.run([sys.executable, SCRIPT, tracks, truth, "--lags", "0.01", *args],
                          capture_output=True, text=True)


class TrackErrorTails(unittest.TestCase):
    def test_shares_and_runs_beyond_the_thresholds(self):
        # Errors along x, px: track 1 has a run of three points beyond 2 px
        # and then one of one; track 2 starts with two (a run of its own, not
        # joined to track 1's last) and holds a 9 px loss that is left out.
        errors = {1: [0.5, 2.5, 2.5, 2.5, 0.5, 1.5, 3.5], 2: [2.5, 2.5, 0.5, 9.0, 0.5]}
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            rows_t, rows_g = [], []
            for fid, es in errors.items():
                for k, e in enumerate(es):
                    t = 0.01 * k
                    rows_g.append((fid, t, 100.0 + k, 50.0))
                    rows_t.append((fid, t, 100.0 + k + e, 50.0))
            write(tracks, rows_t)
            write(truth, rows_g)
            r = run(tracks, truth, "--off-px", "2", "--off-run", "2")
            self.assertEqual(r.returncode, 0, r.stderr)
            # 11 points kept: beyond 1 px 7 (63.6 %), beyond 2 px 6 (54.5 %),
            # beyond 3 px 1 (9.1 %); runs beyond 2 px: 3, 1 and 2 points,
            # two of at least 2 points, holding 5.
            self.assertIn("points beyond 1 / 2 / 3 px: 63.6 % / 54.5 % / 9.1 %", r.stdout)
            self.assertIn("runs beyond 2 px: 3; 2 of at least 2 points, holding 5 points", r.stdout)

    def test_a_loss_left_out_does_not_split_a_run(self):
        # The 9 px point (past --max-error) is left out, as everywhere else
        # in the script: the off points on either side are consecutive kept
        # points and make one run.
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            es = [2.5, 9.0, 2.5, 0.5]
            write(truth, [(1, 0.01 * k, 10.0, 10.0) for k in range(len(es))])
            write(tracks, [(1, 0.01 * k, 10.0 + e, 10.0) for k, e in enumerate(es)])
            r = run(tracks, truth, "--off-run", "2")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("runs beyond 2 px: 1; 1 of at least 2 points, holding 2 points", r.stdout)


class TrackErrorLagModel(unittest.TestCase):
    def test_a_known_lag_is_fitted_and_removed(self):
        # Three tracks at constant image velocity (100 px/s along x, 300 px/s
        # along x, 200 px/s along y), each trailing its truth by exactly
        # a + tau |v| along the motion, a = 0.5 px, tau = 2 ms: 0.7, 1.1 and
        # 0.9 px. The least-squares fit recovers a and tau exactly, and what
        # is left is no error at all.
        a, tau = 0.5, 0.002
        velocities = {1: (100.0, 0.0), 2: (300.0, 0.0), 3: (0.0, 200.0)}
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            rows_t, rows_g = [], []
            for fid, (vx, vy) in velocities.items():
                speed = (vx * vx + vy * vy) ** 0.5
                lag = a + tau * speed
                for k in range(50):
                    t = 0.01 * k
                    x, y = 20.0 + vx * t, 30.0 + vy * t
                    rows_g.append((fid, t, x, y))
                    rows_t.append((fid, t, x - lag * vx / speed, y - lag * vy / speed))
            write(tracks, rows_t)
            write(truth, rows_g)
            plain = run(tracks, truth)
            self.assertEqual(plain.returncode, 0, plain.stderr)
            # Without the model the error is the lag: RMS along x over the
            # 150 points sqrt((50 * 0.7² + 50 * 1.1²) / 150) = 0.753 px, along y
            # sqrt(50 * 0.9² / 150) = 0.520 px.
            self.assertIn("RMS error x 0.753 px  y 0.520 px", plain.stdout)
            r = run(tracks, truth, "--lag-model")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("lag removed: a = 0.500 px, tau = 2.00 ms", r.stdout)
            self.assertIn("RMS error x 0.000 px  y 0.000 px", r.stdout)


    def test_points_measured_on_frames_are_left_out_of_the_lag(self):
        # Two tracks at 100 and 300 px/s along x start with two points on
        # frames (t = 0 and 0.05 s, listed in images.txt), exactly on their
        # truth, then trail it by a + tau |v| (a = 0.5 px, tau = 2 ms). With
        # --frames the fit takes the event points alone and recovers a and
        # tau exactly, and nothing is left; without it the frame points'
        # zero lag pulls the fit off and leaves an error.
        a, tau = 0.5, 0.002
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            images = os.path.join(root, "images.txt")
            with open(images, "w") as f:
                f.write("# timestamp filename\n0.000000000 images/0.png\n0.050000000 images/1.png\n")
            rows_t, rows_g = [], []
            for fid, vx in ((1, 100.0), (2, 300.0)):
                for k, t in enumerate([0.0, 0.05] + [0.052 + 0.004 * j for j in range(40)]):
                    x = 20.0 + vx * t
                    rows_g.append((fid, t, x, 30.0))
                    rows_t.append((fid, t, x if k < 2 else x - (a + tau * vx), 30.0))
            write(tracks, rows_t)
            write(truth, rows_g)
            r = run(tracks, truth, "--lag-model", "--frames", images)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("lag removed: a = 0.500 px, tau = 2.00 ms", r.stdout)
            self.assertIn("points measured on frames, left as they are: 4", r.stdout)
            self.assertIn("RMS error x 0.000 px  y 0.000 px", r.stdout)
            plain = run(tracks, truth, "--lag-model")
            self.assertEqual(plain.returncode, 0, plain.stderr)
            self.assertNotIn("RMS error x 0.000 px", plain.stdout)
            refused = run(tracks, truth, "--frames", images)
            self.assertNotEqual(refused.returncode, 0)
            self.assertIn("--frames needs --lag-model", refused.stderr)


class TrackErrorCommonMode(unittest.TestCase):
    def test_a_shift_shared_by_every_feature_is_measured_exactly(self):
        # Ten still features, one point each in four 10 ms bins. Along x every
        # feature carries the bin's common shift (+0.3, -0.3, +0.3, -0.3 px)
        # plus its own +0.4 px (features 0-4) or -0.4 px (5-9); y is exact.
        # Per bin: the all-feature mean is (±0.3, 0), |m|²/2 = 0.045 px²; the
        # spread around it, per axis with divisor n - 1, is
        # 10 · 0.4² / (2 · 9) = 0.0889 px², and 0.0889 / 10 = 0.0089 px² is what
        # the mean's variance would be with independent errors: ratio 5.06.
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            rows_t, rows_g = [], []
            for fid in range(10):
                own = 0.4 if fid < 5 else -0.4
                for b, shift in enumerate((0.3, -0.3, 0.3, -0.3)):
                    t = 0.005 + 0.01 * b
                    rows_g.append((fid, t, 20.0 * fid, 50.0))
                    rows_t.append((fid, t, 20.0 * fid + shift + own, 50.0))
            write(tracks, rows_t)
            write(truth, rows_g)
            r = run(tracks, truth, "--common-bin", "0.01")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("common to the features, bins of 10 ms: 4 bins, 10 features per bin; "
                          "all-feature mean 0.0450 px² per axis, 0.0089 if independent, ratio 5.06", r.stdout)
            # With a minimum of 11 features per bin no bin qualifies.
            r = run(tracks, truth, "--common-bin", "0.01", "--common-min-features", "11")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("0 bins", r.stdout)
            # One feature has no spread: refused with one clear line.
            r = run(tracks, truth, "--common-bin", "0.01", "--common-min-features", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--common-min-features must be at least 2", r.stderr)
            # Lags of bins without bins: refused too.
            r = run(tracks, truth, "--common-lags", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--common-lags needs --common-bin", r.stderr)


class TrackErrorIntegratedTime(unittest.TestCase):
    def test_constant_and_square_wave_errors(self):
        # Constant errors (0.5, 0) px on three still tracks of 1 s: c(L) = 1 at
        # every lag, so T is the last lag, 200 ms, with no zero; the RMS per
        # axis is sqrt(0.25 / 2) = 0.354 px and at tau = 50 ms the sigma to
        # state is 0.354 sqrt(200 / 50) = 0.71 px.
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            rows_t, rows_g = [], []
            for fid in range(3):
                for k in range(101):
                    t = 0.01 * k
                    rows_g.append((fid, t, 30.0 * fid, 40.0))
                    rows_t.append((fid, t, 30.0 * fid + 0.5, 40.0))
            write(tracks, rows_t)
            write(truth, rows_g)
            r = subprocess.run([sys.executable, SCRIPT, tracks, truth, "--lags", "0.01,0.1,0.2",
                                "--equivalent-at", "0.05"], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("integrated correlation time 200.0 ms (no zero within the lags, to 200 ms)", r.stdout)
            self.assertIn("sigma to state with an exponential weighting of 50 ms: 0.71 px (RMS 0.354 px per axis)",
                          r.stdout)
        # A square wave of period 0.2 s (±0.5 px, points 1 ms apart): c(L) =
        # 1 − 4L/0.2 up to L = 0.1 s, zero at 50 ms, so T is the triangle's
        # area, 25 ms (within 1 ms: the stamps are written to 1 ms).
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            rows_t, rows_g = [], []
            for k in range(2001):
                t = 0.001 * k + 0.0005
                sign = 1.0 if int(t / 0.1) % 2 == 0 else -1.0
                rows_g.append((0, t, 60.0, 40.0))
                rows_t.append((0, t, 60.0 + 0.5 * sign, 40.0))
            write(tracks, rows_t)
            write(truth, rows_g)
            r = subprocess.run([sys.executable, SCRIPT, tracks, truth, "--lags", "0.01,0.02,0.04,0.06,0.1"],
                               capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            m = re.search(r"integrated correlation time ([0-9.]+) ms \(to its first zero\)", r.stdout)
            self.assertIsNotNone(m, r.stdout)
            self.assertAlmostEqual(float(m.group(1)), 25.0, delta=1.0)


class TrackErrorSharedCorrelation(unittest.TestCase):
    def test_the_shared_part_is_told_from_the_features_own(self):
        # Ten still features, one point per 10 ms bin for 30 s. Each point's
        # error is a shift shared by all (first-order, per axis σ 0.2 px,
        # correlation 0.6 from bin to bin) plus the feature's own (σ 1 px,
        # 0.9 from bin to bin). The shared part's variance is 0.04 px² and
        # its correlation 0.6 one bin apart and 0.36 two apart. Without
        # removing the features' own part the bin means would correlate at
        # (0.6 · 0.04 + 0.9 · 0.1) / 0.14 = 0.81 one bin apart.
        import numpy as np
        rng = np.random.default_rng(5)
        n_bins, n_feat = 3000, 10
        shared = np.zeros((n_bins, 2))
        own = np.zeros((n_bins, n_feat, 2))
        shared[0] = rng.normal(0, 0.2, 2)
        own[0] = rng.normal(0, 1.0, (n_feat, 2))
        for b in range(1, n_bins):
            shared[b] = 0.6 * shared[b - 1] + np.sqrt(1 - 0.36) * rng.normal(0, 0.2, 2)
            own[b] = 0.9 * own[b - 1] + np.sqrt(1 - 0.81) * rng.normal(0, 1.0, (n_feat, 2))
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = os.path.join(root, "t.txt"), os.path.join(root, "truth.txt")
            with open(tracks, "w") as ft, open(truth, "w") as fg:
                for f in range(n_feat):
                    for b in range(n_bins):
                        t = 0.01 * b + 0.005
                        e = shared[b] + own[b, f]
                        fg.write(f"{f} {t:.3f} {20.0 * f} 50.0\n")
                        ft.write(f"{f} {t:.3f} {20.0 * f + e[0]:.6f} {50.0 + e[1]:.6f}\n")
            r = subprocess.run([sys.executable, SCRIPT, tracks, truth, "--lags", "0.01", "--max-error", "100",
                                "--common-bin", "0.01", "--common-lags", "1,2"], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            m = re.search(r"all-feature mean ([0-9.]+) px² per axis, ([0-9.]+) if independent", r.stdout)
            self.assertIsNotNone(m, r.stdout)
            self.assertAlmostEqual(float(m.group(1)) - float(m.group(2)), 0.04, delta=0.008)
            corr = {int(k): float(c) for k, c in
                    re.findall(r"shared part (\d+) bins .* correlation (-?[0-9.]+)", r.stdout)}
            self.assertAlmostEqual(corr[1], 0.6, delta=0.1)
            self.assertAlmostEqual(corr[2], 0.36, delta=0.1)


if __name__ == "__main__":
    unittest.main()
