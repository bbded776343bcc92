#!/usr/bin/python3
"""experiments/scripts/nees_over_time.py on a hand-made campaign folder: the
per-bin means are the arithmetic means of the poses' NEES over every run of a
(scenario, method), NaN poses skipped, other methods and non-job folders
ignored, empty bins "-"; a folder without jobs/ is one clear error."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "experiments", "scripts", "nees_over_time.py")


def write_job(root, name, rows):
    folder = os.path.join(root, "jobs", name)
    os.makedirs(folder)
    with open(os.path.join(folder, "metrics_poses.csv"), "w") as f:
        f.write("t_s,distance_m,nees_position,nees_orientation,nees_pose\n")
        for t, p, o in rows:
            f.write(f"{t},0,{p},{o},{p + o}\n")


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class NeesOverTime(unittest.TestCase):
    def test_means_per_bin_over_runs(self):
        with tempfile.TemporaryDirectory() as root:
            write_job(root, "poster.eklt-vio.s1.aaaa", [(0.1, 2.0, 4.0), (0.6, 4.0, 2.0), (1.2, 10.0, 1.0)])
            write_job(root, "poster.eklt-vio.s2.bbbb", [(0.3, 6.0, 3.0), (1.9, float("nan"), 5.0), (1.5, 20.0, 3.0)])
            write_job(root, "poster.klt-vio.s1.cccc", [(0.1, 100.0, 100.0)])
            os.makedirs(os.path.join(root, "jobs", "not-a-job"))
            r = run(root, "--end-s", "3", "--methods", "eklt-vio")
            self.assertEqual(r.returncode, 0, r.stderr)
            lines = r.stdout.strip().splitlines()
            self.assertEqual(len(lines), 2, r.stdout)
            # bin 0: position (2 + 4 + 6) / 3 = 4, orientation (4 + 2 + 3) / 3 = 3;
            # bin 1: the NaN pose skipped, (10 + 20) / 2 = 15 and (1 + 3) / 2 = 2; bin 2 empty.
            self.assertEqual(lines[1], "poster eklt-vio 2 | 4.0 / 3.0 | 15.0 / 2.0 | -")

    def test_a_folder_without_jobs_is_an_error(self):
        with tempfile.TemporaryDirectory() as root:
            r = run(root)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("no jobs/ folder", r.stderr)


if __name__ == "__main__":
    unittest.main()
