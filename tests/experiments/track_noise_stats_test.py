#!/usr/bin/python3
"""experiments/scripts/track_noise_stats.py on hand-made tracks whose errors
are known exactly. Two tracks move at 100 px/s along x, points 10 ms apart,
both trailing their truth by 0.8 px; across the motion track 1 (quality
0.96) is ±0.5 px off and track 2 (quality 0.75) ±1.5 px, each stating 4 px²
per axis. The first and last truth point of each track, a point without a
stated covariance and a 9 px loss are left out."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "experiments", "scripts", "track_noise_stats.py")
LAG_PX = 0.8


def write_case(root):
    tracks, truth, noise = [], [], []
    for fid, quality, cross in ((1, 0.96, 0.5), (2, 0.75, 1.5)):
        for k in range(32):
            t = 0.01 * k
            x, y = 10.0 + 100.0 * t, 20.0 * fid
            ey = cross if k % 2 == 0 else -cross
            if fid == 1 and k == 5:
                ey = 9.0  # a gross loss
            truth.append(f"{fid} {t:.3f} {x} {y}")
            tracks.append(f"{fid} {t:.3f} {x - LAG_PX} {y + ey}")
            stated = "0 0 0" if (fid == 2 and k == 7) else "4 0 4"
            noise.append(f"{fid} {t:.3f} {quality} {stated}")
    paths = [os.path.join(root, n) for n in ("t.txt", "truth.txt", "t.txt.noise.txt")]
    for path, rows in zip(paths, (tracks, truth, noise)):
        with open(path, "w") as f:
            f.write("# hand-made\n" + "\n".join(rows) + "\n")
    return paths[0], paths[1]


def run(tracks, truth, *args):
    return subprocess.run([sys.executable, SCRIPT, tracks, truth, *args], capture_output=True, text=True)


class TrackNoiseStats(unittest.TestCase):
    def test_bands_with_the_lag_removed(self):
        with tempfile.TemporaryDirectory() as root:
            r = run(*write_case(root), "--lag-model")
            self.assertEqual(r.returncode, 0, r.stderr)
            # One speed: the fit's a is the mean lag, 0.8 px, τ 0. Left: the
            # cross errors. Track 1: 29 points (32 − first − last − the
            # loss), mean square per axis 0.5²/2 = 0.125 px², NEES per dof
            # 0.25 / 4 / 2 = 0.03125; track 2: 29 points (32 − 2 − the
            # unstated one), 1.5²/2 = 1.125 px², 0.28125.
            self.assertIn("lag removed: a = 0.800 px, tau = 0.00 ms", r.stdout)
            self.assertIn("[0.70, 0.80)        29        0.0 %        1.125   4.000      0.28", r.stdout)
            self.assertIn("[0.95, 1.00]        29        0.0 %        0.125   4.000      0.03", r.stdout)
            # Two bands, so both fits are exact: cost 0.08 and 0.5;
            # cost²: k = 1.0 / (0.25 − 0.0064) = 4.105, v0 = 0.125 − 4.105 · 0.0064 = 0.099.
            self.assertIn("mean square per axis ≈ 0.099 px² + 4.105 px² · cost²  (weighted rms misfit 0.000 px²)",
                          r.stdout)

    def test_the_lag_counts_as_error_without_the_model(self):
        with tempfile.TemporaryDirectory() as root:
            r = run(*write_case(root))
            self.assertEqual(r.returncode, 0, r.stderr)
            # (0.8² + 1.5²)/2 = 1.445 px²; |e| = 1.70 px and 0.94 px, none beyond 2 px.
            self.assertIn("[0.70, 0.80)        29        0.0 %        1.445", r.stdout)
            self.assertIn("[0.95, 1.00]        29        0.0 %        0.445", r.stdout)

    def test_a_sidecar_of_the_wrong_shape_is_one_error(self):
        with tempfile.TemporaryDirectory() as root:
            tracks, truth = write_case(root)
            with open(tracks + ".noise.txt", "w") as f:
                f.write("1 0.000 0.9 4 0\n")
            r = run(tracks, truth)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("expected 6 columns", r.stderr)


if __name__ == "__main__":
    unittest.main()
