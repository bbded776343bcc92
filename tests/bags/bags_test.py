"""evio import / export against bags written and read by Debian's python3-rosbag.

Usage: /usr/bin/python3 bags_test.py <evio binary> <repository> <scratch folder>
Every comparison is exact (times to the nanosecond, doubles bit for bit)
unless a tolerance is stated beside it.
"""
import filecmp
import json
import os
import random
import shutil
import subprocess
import sys
import unittest

import numpy as np
import rosbag
from geometry_msgs.msg import PoseStamped
from PIL import Image as PilImage
from sensor_msgs.msg import CameraInfo, Image, Imu
from std_msgs.msg import String

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ros_fixture as fx  # noqa: E402

EVIO, REPO, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
T0_NS = 1468939993 * 10**9 + 67_416_301  # an epoch stamp like the Event-Camera Dataset's
WIDTH, HEIGHT = 240, 180


def run(*args):
    return subprocess.run([EVIO, *args], capture_output=True, text=True, timeout=600)


def seconds_to_ns(text):
    whole, frac = text.split(".")
    assert len(frac) == 9, text
    return int(whole) * 10**9 + int(frac)


class Data:
    """A recording of known content: events in messages, frames, IMU, poses, calibration."""

    def __init__(self, seed):
        rng = random.Random(seed)
        t = T0_NS
        self.event_messages = []
        for _ in range(7):
            events = []
            for _ in range(rng.randint(1, 40)):
                t += rng.randint(0, 30_000)  # equal times allowed
                events.append((rng.randrange(WIDTH), rng.randrange(HEIGHT), t, rng.random() < 0.5))
            self.event_messages.append(events)
        self.frames = []
        for i in range(4):
            pixels = np.array([[rng.randrange(256) for _ in range(WIDTH)] for _ in range(HEIGHT)], dtype=np.uint8)
            self.frames.append((T0_NS + 1 + i * 45_123_457, pixels))
        self.imu = [(T0_NS + 3 + i * 1_000_001, [rng.uniform(-20, 20) for _ in range(3)],
                     [rng.uniform(-5, 5) for _ in range(3)]) for i in range(50)]
        self.poses = []
        for i in range(20):
            q = np.array([rng.gauss(0, 1) for _ in range(4)])
            q /= np.linalg.norm(q)
            self.poses.append((T0_NS + 7 + i * 4_999_999, [rng.uniform(-3, 3) for _ in range(3)], list(q)))
        self.K = [199.092366542, 0, 132.192071378, 0, 198.82882047, 110.712660011, 0, 0, 1]
        self.D = [-0.368436311798, 0.150947243557, -0.000296130534385, -0.000759431726241, 0.0]

    def all_events(self):
        return [e for m in self.event_messages for e in m]

    def write(self, path, compression="none", events_mode="raw", image_encoding="mono8", md5=None, full_text=None):
        md5_, full_ = fx.genmsg_dvs()[:2]
        bag = fx.open_bag(path, compression)
        try:
            info = CameraInfo()
            info.header.stamp = fx.ros_time(T0_NS)
            info.width, info.height = WIDTH, HEIGHT
            info.distortion_model = "plumb_bob"
            info.K, info.D = self.K, self.D
            bag.write("/dvs/camera_info", info, fx.ros_time(T0_NS))
            fx.write_events(bag, "/dvs/events", self.event_messages, WIDTH, HEIGHT, events_mode, md5 or md5_,
                            full_text or full_)
            for t, pixels in self.frames:
                msg = Image()
                msg.header.stamp = fx.ros_time(t)
                msg.height, msg.width = pixels.shape
                if image_encoding == "mono8":
                    msg.encoding, msg.step, msg.data = "mono8", WIDTH, pixels.tobytes()
                else:  # the same grey in all three channels converts back exactly
                    msg.encoding, msg.step = "rgb8", 3 * WIDTH
                    msg.data = np.repeat(pixels[:, :, None], 3, axis=2).tobytes()
                bag.write("/dvs/image_raw", msg, fx.ros_time(t))
            # Recorded in arrival order: a stamp out of order shows only in the header.
            arrivals = sorted(t for t, _, _ in self.imu)
            for (t, acc, gyro), arrival in zip(self.imu, arrivals):
                msg = Imu()
                msg.header.stamp = fx.ros_time(t)
                msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = acc
                msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = gyro
                bag.write("/dvs/imu", msg, fx.ros_time(arrival))
            for t, p, q in self.poses:
                msg = PoseStamped()
                msg.header.stamp = fx.ros_time(t)
                msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = p
                o = msg.pose.orientation
                o.x, o.y, o.z, o.w = q
                bag.write("/optitrack/davis", msg, fx.ros_time(t))
        finally:
            bag.close()


def read_rows(path):
    with open(path) as f:
        return [line.split() for line in f if line.strip() and not line.startswith("#")]


class PublishedDefinition(unittest.TestCase):
    def test_genmsg_gives_the_published_md5(self):
        md5, _, event_md5 = fx.genmsg_dvs()
        self.assertEqual(md5, fx.PUBLISHED_EVENT_ARRAY_MD5)
        self.assertEqual(event_md5, "40d339b261445b8ce9a6fef01267cd5d")

    def test_md5_ignores_comments_but_not_fields(self):
        # The sum is over the fields, not the text: a check that it can fail.
        commented = fx.EVENT_ARRAY_MSG.replace("# an array of events\n", "# other words\n")
        self.assertEqual(fx.genmsg_dvs(commented)[0], fx.PUBLISHED_EVENT_ARRAY_MD5)
        swapped = fx.EVENT_ARRAY_MSG.replace("uint32 height", "uint32 h")
        self.assertNotEqual(fx.genmsg_dvs(swapped)[0], fx.PUBLISHED_EVENT_ARRAY_MD5)


class ImportIndependentBags(unittest.TestCase):
    def setUp(self):
        self.dir = os.path.join(WORK, self.id().split(".")[-1])
        shutil.rmtree(self.dir, ignore_errors=True)
        os.makedirs(self.dir)
        self.data = Data(seed=21)

    def imported(self, bag, *extra):
        out = os.path.join(self.dir, "seq")
        r = run("import", bag, "-o", out, "-q", "--topic", "groundtruth=/optitrack/davis", *extra)
        self.assertEqual(r.returncode, 0, r.stderr)
        return out

    def check_folder(self, seq):
        d = self.data
        rows = read_rows(os.path.join(seq, "events.txt"))
        got = [(int(x), int(y), seconds_to_ns(t), p == "1") for t, x, y, p in rows]
        self.assertEqual(got, d.all_events())
        rows = read_rows(os.path.join(seq, "images.txt"))
        self.assertEqual([seconds_to_ns(t) for t, _ in rows], [t for t, _ in d.frames])
        for (_, name), (_, pixels) in zip(rows, d.frames):
            with PilImage.open(os.path.join(seq, name)) as im:
                self.assertEqual(im.mode, "L")
                np.testing.assert_array_equal(np.asarray(im), pixels)
        rows = read_rows(os.path.join(seq, "imu.txt"))
        self.assertEqual([(seconds_to_ns(r[0]), [float(v) for v in r[1:4]], [float(v) for v in r[4:7]]) for r in rows],
                         d.imu)
        rows = read_rows(os.path.join(seq, "groundtruth.txt"))
        self.assertEqual(len(rows), len(d.poses))
        for r, (t, p, q) in zip(rows, d.poses):
            self.assertEqual(seconds_to_ns(r[0]), t)
            self.assertEqual([float(v) for v in r[1:4]], p)
            # evio renormalises a quaternion whose squared norm is off 1 by more than 4e-16.
            np.testing.assert_allclose([float(v) for v in r[4:8]], q, rtol=0, atol=1e-15)
        (calib,) = read_rows(os.path.join(seq, "calib.txt"))
        K = d.K
        self.assertEqual([float(v) for v in calib], [K[0], K[4], K[2], K[5]] + d.D)

    def test_uncompressed_raw_events(self):
        bag = os.path.join(self.dir, "a.bag")
        self.data.write(bag, "none", "raw")
        self.check_folder(self.imported(bag))

    def test_bz2_genpy_events(self):
        bag = os.path.join(self.dir, "a.bag")
        self.data.write(bag, "bz2", "genpy")
        self.check_folder(self.imported(bag))

    def test_lz4_raw_events_rgb_frames(self):
        bag = os.path.join(self.dir, "a.bag")
        self.data.write(bag, "lz4", "raw", image_encoding="rgb8")
        self.check_folder(self.imported(bag))

    def test_same_bag_gives_identical_folders(self):
        bag = os.path.join(self.dir, "a.bag")
        self.data.write(bag, "lz4", "raw")
        first = self.imported(bag)
        os.rename(first, first + "1")
        second = self.imported(bag)
        self.assertEqual(sorted(os.listdir(first + "1")), sorted(os.listdir(second)))
        for name in ["events.txt", "images.txt", "imu.txt", "groundtruth.txt", "calib.txt"] + \
                [os.path.join("images", f) for f in os.listdir(os.path.join(second, "images"))]:
            self.assertTrue(filecmp.cmp(os.path.join(first + "1", name), os.path.join(second, name), shallow=False), name)

    def test_imported_folder_is_a_sequence(self):
        bag = os.path.join(self.dir, "a.bag")
        self.data.write(bag, "none", "raw")
        seq = self.imported(bag)
        r = run("info", seq, "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        info = json.loads(r.stdout)
        self.assertEqual(info["events"]["count"], len(self.data.all_events()), r.stdout)
        for args in (["stats", seq, "--json"], ["track", seq, "--frontend", "klt", "-o", os.path.join(self.dir, "t.txt")]):
            r = run(*args)
            self.assertEqual(r.returncode, 0, r.stderr)


class BadBags(unittest.TestCase):
    """One evio error naming the bag and what is wrong; no output folder."""

    def setUp(self):
        self.dir = os.path.join(WORK, self.id().split(".")[-1])
        shutil.rmtree(self.dir, ignore_errors=True)
        os.makedirs(self.dir)
        self.bag = os.path.join(self.dir, "bad.bag")

    def expect_error(self, words, *extra):
        out = os.path.join(self.dir, "seq")
        r = run("import", self.bag, "-o", out, *extra)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        lines = r.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith("evio: error: "), lines[0])
        self.assertNotIn("internal", lines[0])
        for w in words:
            self.assertIn(w, lines[0])
        self.assertEqual(sorted(os.listdir(self.dir)), ["bad.bag"])  # nothing published, no staging left
        return lines[0]

    def test_truncated(self):
        good = os.path.join(WORK, "good_for_truncation.bag")
        Data(3).write(good)
        with open(good, "rb") as f:
            data = f.read()
        with open(self.bag, "wb") as f:
            f.write(data[: len(data) * 2 // 3])
        self.expect_error([self.bag, "truncated"])

    def test_not_a_bag(self):
        with open(self.bag, "w") as f:
            f.write("0.1 2 3 1\n" * 100)
        self.expect_error([self.bag, "not a ROS 1 bag"])

    def test_override_of_the_wrong_type(self):
        Data(3).write(self.bag)
        self.expect_error([self.bag, "/dvs/imu", "sensor_msgs/Imu", "dvs_msgs/EventArray"], "--topic", "events=/dvs/imu")

    def test_override_of_a_missing_topic(self):
        Data(3).write(self.bag)
        self.expect_error([self.bag, "/nothing", "no such topic"], "--topic", "imu=/nothing")

    def test_other_event_layout(self):
        # rpg_dvs_ros's older layout with a different field order has another MD5.
        Data(3).write(self.bag, md5="732c9cc0676a970b9aa2873b0d444ac2")
        self.expect_error([self.bag, "/dvs/events", "MD5", "732c9cc0676a970b9aa2873b0d444ac2"])

    def test_two_image_topics(self):
        Data(3).write(self.bag)
        with rosbag.Bag(self.bag, "a") as bag:
            msg = Image(height=1, width=1, encoding="mono8", step=1, data=b"\x00")
            msg.header.stamp = fx.ros_time(T0_NS + 5)
            bag.write("/dvs_rendering", msg, fx.ros_time(T0_NS + 5))
        self.expect_error([self.bag, "/dvs/image_raw", "/dvs_rendering", "--topic frames="])

    def test_topic_with_two_types(self):
        Data(3).write(self.bag)
        with rosbag.Bag(self.bag, "a") as bag:
            bag.write("/dvs/imu", String(data="not an IMU"), fx.ros_time(T0_NS + 5))
        self.expect_error([self.bag, "/dvs/imu", "two message types", "std_msgs/String"])

    def test_unsorted_imu(self):
        d = Data(3)
        d.imu[10], d.imu[11] = d.imu[11], d.imu[10]
        d.write(self.bag)
        self.expect_error([self.bag, "/dvs/imu message 11", "unsorted"])

    def test_unsorted_events(self):
        d = Data(3)
        d.event_messages[2].reverse()
        if len(d.event_messages[2]) < 2 or d.event_messages[2][0][2] == d.event_messages[2][-1][2]:
            d.event_messages[2] = [(1, 1, T0_NS + 10**8, 1), (1, 1, T0_NS, 1)]
        d.write(self.bag)
        self.expect_error([self.bag, "/dvs/events message 2", "not sorted"])

    def test_event_outside_the_sensor(self):
        d = Data(3)
        x, y, t, p = d.event_messages[1][0]
        d.event_messages[1][0] = (WIDTH, y, t, p)
        d.write(self.bag)
        self.expect_error([self.bag, "/dvs/events message 1", "outside the 240 x 180 sensor"])

    def test_random_damage_never_crashes(self):
        # Seeded random bytes overwritten (and sometimes the end cut off) in
        # bags of each compression: exit 0 (damage in bytes nothing checks, as
        # ROS 1 bags carry no checksum) or one evio error, never a crash,
        # an internal error or a hang.
        rng = random.Random(21)
        for compression in ("none", "bz2", "lz4"):
            good = os.path.join(WORK, "good_random_%s.bag" % compression)
            Data(7).write(good, compression)
            with open(good, "rb") as f:
                data = f.read()
            for _ in range(15):
                d = bytearray(data)
                for _ in range(rng.choice([1, 8, 64])):
                    d[rng.randrange(len(d))] = rng.randrange(256)
                if rng.random() < 0.2:
                    d = d[: rng.randrange(len(d))]
                with open(self.bag, "wb") as f:
                    f.write(d)
                out = os.path.join(self.dir, "seq")
                r = subprocess.run([EVIO, "import", self.bag, "-o", out, "-q"], capture_output=True, timeout=120)
                self.assertIn(r.returncode, (0, 1), r.stderr)
                if r.returncode == 1:
                    self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
                    self.assertTrue(r.stderr.startswith(b"evio: error: "), r.stderr)
                    self.assertFalse(os.path.exists(out))
                shutil.rmtree(out, ignore_errors=True)

    def corrupt_chunk(self, compression):
        good = os.path.join(WORK, "good_%s.bag" % compression)
        Data(5).write(good, compression)
        with open(good, "rb") as f:
            data = bytearray(f.read())
        # The chunk's data starts after the bag header record (4096 bytes of
        # header plus padding) and the chunk record's header; damage the middle
        # of the first chunk, leaving the index at the end intact.
        start = data.index(b"compression=" + compression.encode())
        for i in range(start + 200, start + 600):
            data[i] ^= 0x5A
        with open(self.bag, "wb") as f:
            f.write(data)

    def test_corrupt_bz2_chunk(self):
        self.corrupt_chunk("bz2")
        self.expect_error([self.bag, "corrupt"])

    def test_corrupt_lz4_chunk(self):
        self.corrupt_chunk("lz4")
        self.expect_error([self.bag, "corrupt"])


class ExportReadByRosbag(unittest.TestCase):
    """A simulated sequence exported, read back by python3-rosbag, and imported again."""

    @classmethod
    def setUpClass(cls):
        cls.dir = os.path.join(WORK, "export")
        shutil.rmtree(cls.dir, ignore_errors=True)
        os.makedirs(cls.dir)
        cls.seq = os.path.join(cls.dir, "sim")
        r = run("simulate", os.path.join(REPO, "experiments/scenarios/poster_rotation.yaml"), "-o", cls.seq, "-q",
                "--set", "duration_s=0.3")
        assert r.returncode == 0, r.stderr

    def export(self, compression, name=None):
        bag = os.path.join(self.dir, name or compression + ".bag")
        r = run("export", self.seq, "--format", "rosbag", "--compression", compression, "-o", bag, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        return bag

    def check_read_by_rosbag(self, path):
        seq = self.seq
        md5, full_text, _ = fx.genmsg_dvs()
        with rosbag.Bag(path) as bag:
            types = {t: (i.msg_type, i.message_count) for t, i in bag.get_type_and_topic_info().topics.items()}
            self.assertEqual(types["/dvs/events"][0], "dvs_msgs/EventArray")
            conns = {c.topic: c for c in bag._get_connections()}
            self.assertEqual(conns["/dvs/events"].md5sum, fx.PUBLISHED_EVENT_ARRAY_MD5)
            self.assertEqual(conns["/dvs/events"].msg_def, full_text)  # the definition genmsg builds
            events, frames, imu, poses = [], [], [], []
            for topic, msg, t in bag.read_messages():
                if topic == "/dvs/events":
                    self.assertEqual((msg.width, msg.height), (240, 180))
                    events += [(e.ts.to_nsec(), e.x, e.y, int(e.polarity)) for e in msg.events]
                    self.assertEqual(msg.header.stamp.to_nsec(), msg.events[-1].ts.to_nsec())
                elif topic == "/dvs/image_raw":
                    self.assertEqual(msg.encoding, "mono8")
                    frames.append((msg.header.stamp.to_nsec(),
                                   np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.width)))
                elif topic == "/dvs/imu":
                    imu.append([msg.header.stamp.to_nsec()] + [msg.linear_acceleration.x, msg.linear_acceleration.y,
                                                               msg.linear_acceleration.z, msg.angular_velocity.x,
                                                               msg.angular_velocity.y, msg.angular_velocity.z])
                elif topic == "/groundtruth/pose":
                    p, o = msg.pose.position, msg.pose.orientation
                    poses.append([msg.header.stamp.to_nsec(), p.x, p.y, p.z, o.x, o.y, o.z, o.w])
                elif topic == "/dvs/camera_info":
                    calib = read_rows(os.path.join(seq, "calib.txt"))[0]
                    fxv, fyv, cx, cy = (float(v) for v in calib[:4])
                    self.assertEqual(list(msg.K), [fxv, 0, cx, 0, fyv, cy, 0, 0, 1])
                    self.assertEqual(list(msg.D), [float(v) for v in calib[4:]])
                    self.assertEqual((msg.width, msg.height, msg.distortion_model), (240, 180, "plumb_bob"))
                elif topic == "/evio/sensors_yaml":
                    with open(os.path.join(seq, "sensors.yaml")) as f:
                        self.assertEqual(msg.data, f.read())
        expected = [(seconds_to_ns(t), int(x), int(y), int(p)) for t, x, y, p in read_rows(os.path.join(seq, "events.txt"))]
        self.assertEqual(events, expected)
        rows = read_rows(os.path.join(seq, "imu.txt"))
        self.assertEqual(imu, [[seconds_to_ns(r[0])] + [float(v) for v in r[1:]] for r in rows])
        rows = read_rows(os.path.join(seq, "groundtruth.txt"))
        self.assertEqual(poses, [[seconds_to_ns(r[0])] + [float(v) for v in r[1:]] for r in rows])
        rows = read_rows(os.path.join(seq, "images.txt"))
        self.assertEqual([t for t, _ in frames], [seconds_to_ns(t) for t, _ in rows])
        for (_, name), (_, pixels) in zip(rows, frames):
            with PilImage.open(os.path.join(seq, name)) as im:
                np.testing.assert_array_equal(np.asarray(im.convert("L")), pixels)

    def test_read_by_rosbag(self):
        for compression in ("none", "bz2", "lz4"):
            with self.subTest(compression=compression):
                self.check_read_by_rosbag(self.export(compression))

    def test_round_trip_is_byte_identical(self):
        bag = self.export("lz4", "round_trip.bag")
        out = os.path.join(self.dir, "imported")
        shutil.rmtree(out, ignore_errors=True)
        r = run("import", bag, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        names = ["events.txt", "images.txt", "imu.txt", "groundtruth.txt", "calib.txt", "sensors.yaml"]
        names += [os.path.join("images", f) for f in sorted(os.listdir(os.path.join(self.seq, "images")))]
        self.assertEqual(sorted(os.listdir(os.path.join(out, "images"))), sorted(os.listdir(os.path.join(self.seq, "images"))))
        for name in names:
            self.assertTrue(filecmp.cmp(os.path.join(self.seq, name), os.path.join(out, name), shallow=False), name)

    def test_imported_sequence_estimates_as_the_original(self):
        bag = self.export("none", "estimate.bag")
        out = os.path.join(self.dir, "imported_for_estimate")
        shutil.rmtree(out, ignore_errors=True)
        self.assertEqual(run("import", bag, "-o", out, "-q").returncode, 0)
        trajectories = []
        for seq in (self.seq, out):
            est = seq + "_estimate"
            r = run("estimate", seq, "--method", "klt-vio", "--init", "groundtruth", "-o", est, "-q")
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(os.path.join(est, "trajectory.txt")) as f:
                trajectories.append([line for line in f if not line.startswith("#")])  # the header names the folder
        self.assertGreater(len(trajectories[0]), 1)
        self.assertEqual(trajectories[0], trajectories[1])

    def test_real_slices_round_trip(self):
        for name in ("shapes_rotation_events", "boxes_6dof_frames"):
            with self.subTest(slice=name):
                src = os.path.join(REPO, "tests/data/ecd", name)
                bag = os.path.join(self.dir, name + ".bag")
                out = os.path.join(self.dir, name)
                shutil.rmtree(out, ignore_errors=True)
                self.assertEqual(run("export", src, "--format", "rosbag", "-o", bag, "-q").returncode, 0)
                self.assertEqual(run("import", bag, "-o", out, "-q").returncode, 0)
                for f in os.listdir(src):
                    if f in ("calib.txt", "images") or f.endswith(".md"):
                        continue
                    self.assertTrue(filecmp.cmp(os.path.join(src, f), os.path.join(out, f), shallow=False), f)
                if os.path.isdir(os.path.join(src, "images")):
                    for f in os.listdir(os.path.join(src, "images")):
                        self.assertTrue(filecmp.cmp(os.path.join(src, "images", f), os.path.join(out, "images", f),
                                                    shallow=False), f)
                # The same numbers, written in their shortest form (0.0 becomes 0).
                self.assertEqual([float(v) for v in read_rows(os.path.join(src, "calib.txt"))[0]],
                                 [float(v) for v in read_rows(os.path.join(out, "calib.txt"))[0]])

    def test_export_is_deterministic(self):
        a = self.export("bz2", "a.bag")
        b = self.export("bz2", "b.bag")
        self.assertTrue(filecmp.cmp(a, b, shallow=False))


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
