#!/usr/bin/python3
"""experiments/scripts/track_coverage.py on hand-made tracks whose counts are
known exactly. A 100 x 80 image in a 2 x 2 grid (cells 50 x 40 px), frames at
0, 0.1, 0.2 and 0.3 s:
  track 1: 0.00-0.30 s, at x 10 -> 70 (crosses into the right cells at 0.2 s), y 10;
  track 2: 0.10-0.20 s, at (20, 60) (bottom left);
  track 3: 0.05-0.15 s, at (90, 70) (bottom right), first point between frames;
  track 4: 0.25-0.25 s, a single point between frames (never live at a frame).
Live at the frames: 1, 3 (1, 2, 3), 2 (1, 2), 1 (1): first 1, mean 1.75, min 1.
Cells: {TL}, {TL, BL, BR}, {TR, BL}, {TR}: mean 1.75, min 1.
Lives 0.3, 0.1, 0.1, 0: median 0.1 s."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "experiments", "scripts", "track_coverage.py")


def write(root, name, lines):
    path = os.path.join(root, name)
    with open(path, "w") as f:
        f.write("# hand-made\n" + "\n".join(lines) + "\n")
    return path


def case(root, images=None):
    tracks = ["1 0.00 10 10", "1 0.15 40 10", "1 0.20 70 10", "1 0.30 70 12",
              "2 0.10 20 60", "2 0.20 21 61",
              "3 0.05 90 70", "3 0.15 91 70",
              "4 0.25 5 5"]
    frames = images if images is not None else [f"{t:.1f} images/frame_{k:08d}.png" for k, t in enumerate((0, 0.1, 0.2, 0.3))]
    return write(root, "tracks.txt", tracks), write(root, "images.txt", frames)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class TrackCoverage(unittest.TestCase):
    def test_live_tracks_and_cells_at_each_frame(self):
        with tempfile.TemporaryDirectory() as root:
            r = run(*case(root), "--size", "100x80", "--grid", "2")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("frames 4", r.stdout)
            self.assertIn("live tracks: first frame 1, mean 1.8, min 1", r.stdout)  # 1.75 printed to one decimal
            self.assertIn("covered cells of 4: mean 1.8, min 1", r.stdout)
            self.assertIn("tracks 4, median life 0.100 s", r.stdout)

    def test_bad_frame_time_names_file_line_and_field(self):
        with tempfile.TemporaryDirectory() as root:
            tracks, images = case(root, images=["0.0 a.png", "zero b.png"])
            r = run(tracks, images, "--size", "100x80")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("images.txt:3: field t", r.stderr)

    def test_bad_size_is_refused(self):
        with tempfile.TemporaryDirectory() as root:
            r = run(*case(root), "--size", "100by80")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--size", r.stderr)


if __name__ == "__main__":
    unittest.main()
