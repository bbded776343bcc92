"""Tests of the Python package `evio` (python/), run by ctest under Debian's
/usr/bin/python3 with PYTHONPATH at the built package (build/<preset>/python).

Every array the module returns is checked against an independent reading of
the same files with NumPy (events.txt, imu.txt, groundtruth.txt) or
matplotlib (the PNG frames); the commands against the `evio` binary's own
output for the same command line.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import evio

EVIO_BIN = evio.binary()  # found beside the package, as a user gets it


def seconds_to_ns(column):
    """Text times have 9 decimals: exact nanoseconds, parsed without float rounding."""
    out = []
    for s in column:
        whole, _, frac = s.partition(".")
        out.append(int(whole) * 1_000_000_000 + int((frac + "000000000")[:9]))
    return np.array(out, dtype=np.int64)


class SimulatedSequence(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.seq = os.path.join(cls.tmp.name, "seq")
        cls.summary = evio.simulate(
            "experiments/scenarios/poster_6dof.yaml", cls.seq,
            options={"duration_s": 1.0, "seed": 3, "output": {"write_events_txt": True}})

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def text_events(self):
        rows = np.loadtxt(os.path.join(self.seq, "events.txt"), dtype=str, ndmin=2)
        return seconds_to_ns(rows[:, 0]), rows[:, 1].astype(np.uint16), rows[:, 2].astype(np.uint16), \
            rows[:, 3].astype(np.uint8)

    def test_simulate_returns_its_summary(self):
        self.assertIsInstance(self.summary, dict)
        self.assertGreater(len(self.summary), 0)

    def test_events_equal_the_text_file(self):
        ev = evio.read_events(self.seq)  # events.h5: times floored to whole µs (core/io/events_h5.h)
        t, x, y, p = self.text_events()
        t = (t // 1000) * 1000
        self.assertEqual(ev.dtype.names, ("t", "x", "y", "p"))
        self.assertEqual(ev.dtype.itemsize, 13)
        self.assertGreater(len(ev), 1000)
        np.testing.assert_array_equal(ev["t"], t)
        np.testing.assert_array_equal(ev["x"], x)
        np.testing.assert_array_equal(ev["y"], y)
        np.testing.assert_array_equal(ev["p"], p)

    def test_columns_equal_the_structured_array_and_own_their_memory(self):
        ev = evio.read_events(self.seq)
        cols = evio.read_event_columns(self.seq)
        for name in ("t", "x", "y", "p"):
            np.testing.assert_array_equal(cols[name], ev[name])
            self.assertFalse(cols[name].flags["OWNDATA"])  # over the reader's buffer, not a copy
            self.assertIsNotNone(cols[name].base)

    def test_window_keeps_exactly_the_events_in_it(self):
        ev = evio.read_events(self.seq)
        t0 = int(ev["t"][len(ev) // 3])
        t1 = int(ev["t"][2 * len(ev) // 3])
        win = evio.read_events(self.seq, t_start_ns=t0, t_end_ns=t1)
        mask = (ev["t"] >= t0) & (ev["t"] < t1)
        np.testing.assert_array_equal(win, ev[mask])
        with self.assertRaises(evio.Error):
            evio.read_events(self.seq, t_start_ns=t1, t_end_ns=t0)

    def test_chunks_stream_the_same_events(self):
        ev = evio.read_events(self.seq)
        chunks = list(evio.iter_events(self.seq, chunk_size=1000))
        self.assertTrue(all(len(c) <= 1000 for c in chunks))
        np.testing.assert_array_equal(np.concatenate(chunks), ev)

    def test_imu_and_groundtruth_equal_the_text_files(self):
        imu = evio.read_imu(self.seq)
        rows = np.loadtxt(os.path.join(self.seq, "imu.txt"), dtype=str, ndmin=2)
        np.testing.assert_array_equal(imu["t"], seconds_to_ns(rows[:, 0]))
        # imu.txt: t ax ay az gx gy gz (the Event-Camera Dataset's order: acceleration first)
        np.testing.assert_array_equal(imu["acc"], rows[:, 1:4].astype(float))
        np.testing.assert_array_equal(imu["gyro"], rows[:, 4:7].astype(float))
        gt = evio.read_groundtruth(self.seq)
        rows = np.loadtxt(os.path.join(self.seq, "groundtruth.txt"), dtype=str, ndmin=2)
        np.testing.assert_array_equal(gt["t"], seconds_to_ns(rows[:, 0]))
        np.testing.assert_allclose(gt["p"], rows[:, 1:4].astype(float), rtol=0, atol=0)
        np.testing.assert_allclose(np.abs(gt["q"]), np.abs(rows[:, 4:8].astype(float)), rtol=0, atol=1e-15)

    def test_frames_equal_the_png_files(self):
        import matplotlib.image
        stamps = np.loadtxt(os.path.join(self.seq, "images.txt"), dtype=str, ndmin=2)
        frames = list(evio.iter_frames(self.seq))
        self.assertEqual(len(frames), len(stamps))
        for (t, pixels), (ts, name) in zip(frames, stamps):
            self.assertEqual(t, seconds_to_ns([ts])[0])
            self.assertEqual(pixels.dtype, np.uint8)
            png = np.rint(matplotlib.image.imread(os.path.join(self.seq, name)) * 255).astype(np.uint8)
            np.testing.assert_array_equal(pixels, png)

    def test_frames_in_other_formats_come_through_the_media_module(self):
        # A copy of the sequence's frames as binary PGM (P5): OpenCV reads it
        # through the media module, which the package finds beside itself
        # (the environment names no module here).
        self.assertNotIn("EVIO_MEDIA_MODULE", os.environ)
        frames = list(evio.iter_frames(self.seq))[:3]
        folder = os.path.join(self.tmp.name, "pgm")
        os.makedirs(os.path.join(folder, "images"), exist_ok=True)
        with open(os.path.join(folder, "images.txt"), "w") as listing:
            for k, (t, pixels) in enumerate(frames):
                name = "images/frame_%08d.pgm" % k
                with open(os.path.join(folder, name), "wb") as f:
                    f.write(b"P5\n%d %d\n255\n" % (pixels.shape[1], pixels.shape[0]) + pixels.tobytes())
                listing.write("%d.%09d %s\n" % (t // 1_000_000_000, t % 1_000_000_000, name))
        back = list(evio.iter_frames(folder))
        self.assertEqual(len(back), len(frames))
        for (t, pixels), (t_back, pixels_back) in zip(frames, back):
            self.assertEqual(t, t_back)
            np.testing.assert_array_equal(pixels, pixels_back)

    def test_estimate_and_evaluate_match_the_binary(self):
        est = os.path.join(self.tmp.name, "est")
        status = evio.estimate(self.seq, est, method="klt-vio", config="estimator/config/sim.yaml",
                               options={"backend": {"max_slam_features": 12}}, init="groundtruth")
        self.assertEqual(status["exit_code"], 0)
        self.assertEqual(status["status"], "ok")
        metrics = evio.evaluate(est, self.seq, options={"alignment": {"type": "se3"}})
        out = os.path.join(self.tmp.name, "cli.json")
        subprocess.run([EVIO_BIN, "evaluate", est, self.seq, "--set", "alignment.type=se3", "-o", out, "-q"],
                       check=True)
        with open(out) as f:
            cli = json.load(f)
        self.assertEqual(metrics, cli)

    def test_unknown_option_is_the_clis_error(self):
        with self.assertRaises(evio.Error) as caught:
            evio.estimate(self.seq, os.path.join(self.tmp.name, "bad"), method="klt-vio",
                          options={"backend": {"no_such_option": 1}})
        self.assertIn("no_such_option", str(caught.exception))
        self.assertFalse(os.path.exists(os.path.join(self.tmp.name, "bad")))
        with self.assertRaises(evio.Error):
            evio.simulate("experiments/scenarios/poster_6dof.yaml", os.path.join(self.tmp.name, "bad2"),
                          options={"duration_s": object()})

    def test_missing_files_raise_evio_errors(self):
        with self.assertRaises(evio.Error) as caught:
            evio.read_imu(self.tmp.name)
        self.assertIn("imu.txt", str(caught.exception))
        with self.assertRaises(evio.Error) as caught:
            evio.run(["info", os.path.join(self.tmp.name, "no_such_folder")])
        self.assertIn("no_such_folder", str(caught.exception))


if __name__ == "__main__":
    unittest.main(verbosity=2)
