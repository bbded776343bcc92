#!/usr/bin/python3
"""`evio track --noise` on the real shapes_rotation slice (tests/data/ecd):
the sidecar <output>.noise.txt has one line per track point, in the same
order with the same id and stamp, a quality in [0, 1] and a covariance that
is zero (not stated) or positive definite; a run without --noise removes an
older sidecar, which would not belong to the new tracks. The same for
--lag-compensated (<output>.lag_compensated.txt: id t x y, the same ids and
stamps; that the points move toward the truth: lag_compensated_tracks_test.py).

usage: track_noise_output_test.py <evio> <source dir>"""
import os
import subprocess
import sys
import tempfile
import unittest

EVIO, SOURCE = sys.argv[1], sys.argv[2]


def data_lines(path):
    with open(path) as f:
        return [line.split() for line in f if line.strip() and not line.startswith("#")]


class TrackNoiseOutput(unittest.TestCase):
    def test_sidecar_follows_the_tracks_line_by_line(self):
        folder = os.path.join(SOURCE, "tests", "data", "ecd", "shapes_rotation_events")
        with tempfile.TemporaryDirectory() as root:
            out = os.path.join(root, "t.txt")
            args = [EVIO, "track", folder, "--frontend", "eklt", "--image-source", "reconstructed", "-q", "-o", out]
            r = subprocess.run(args + ["--noise"], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            tracks, noise = data_lines(out), data_lines(out + ".noise.txt")
            self.assertGreater(len(tracks), 50)
            self.assertEqual(len(noise), len(tracks))
            stated = 0
            for t, n in zip(tracks, noise):
                self.assertEqual(len(n), 6)
                self.assertEqual(n[:2], t[:2])  # id and stamp, character for character
                quality, cxx, cxy, cyy = map(float, n[2:])
                self.assertTrue(0.0 <= quality <= 1.0, n)
                if cxx == 0.0 and cxy == 0.0 and cyy == 0.0:
                    continue
                stated += 1
                self.assertGreater(cxx, 0.0, n)
                self.assertGreater(cxx * cyy - cxy * cxy, 0.0, n)
            self.assertGreater(stated, 0)
            r = subprocess.run(args, capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertFalse(os.path.exists(out + ".noise.txt"))

    def test_lag_compensated_sidecar_follows_the_tracks(self):
        folder = os.path.join(SOURCE, "tests", "data", "ecd", "shapes_rotation_events")
        with tempfile.TemporaryDirectory() as root:
            out = os.path.join(root, "t.txt")
            args = [EVIO, "track", folder, "--frontend", "eklt", "--image-source", "reconstructed", "-q", "-o", out]
            r = subprocess.run(args + ["--lag-compensated", "--lag-velocity-window", "0.02"],
                               capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            tracks, moved = data_lines(out), data_lines(out + ".lag_compensated.txt")
            self.assertGreater(len(tracks), 50)
            self.assertEqual([m[:2] for m in moved], [t[:2] for t in tracks])
            r = subprocess.run(args + ["--lag-velocity-window", "2"], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--lag-velocity-window", r.stderr)
            r = subprocess.run(args, capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertFalse(os.path.exists(out + ".lag_compensated.txt"))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
