"""The Python client (client/python/hapticd_client.py) against the real daemon: hapticd runs as a
subprocess on a free loopback port (sim device, the built-in demo scene, no shared memory, no
real-time priority). Contents are asserted, never speed; every wait is bounded.

Run by CTest (client.python) with HAPTICD (the binary) and HAPTICD_SOURCE_DIR set; by hand:
    HAPTICD=build/release/bin/hapticd HAPTICD_SOURCE_DIR=. \\
        python3 -m unittest -v tests/client/python/test_hapticd_client.py
"""

import math
import os
import socket
import subprocess
import sys
import tempfile
import time
import unittest

SOURCE = os.environ.get("HAPTICD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "../../.."))
sys.path.insert(0, os.path.join(SOURCE, "client", "python"))
import hapticd_client as hc  # noqa: E402


def closed_port():
    """A loopback UDP port nothing listens on (bound for a moment, then closed)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Daemon:
    """hapticd as a subprocess on a free loopback port; stop() sends SIGTERM and waits."""

    def __init__(self, *extra):
        binary = os.environ.get("HAPTICD")
        if not binary:
            raise unittest.SkipTest("HAPTICD (the hapticd binary) is not set")
        self.log = tempfile.TemporaryFile(mode="w+")  # its log (a pipe could fill and block it)
        for _ in range(3):  # another program may take the port between the probe and the bind
            self.port = closed_port()
            self.proc = subprocess.Popen(
                [binary, "--udp", f"127.0.0.1:{self.port}", "--shm", "", "--realtime", "off",
                 *extra], stdout=subprocess.DEVNULL, stderr=self.log)
            if self._answers():
                return
            self._end()
        self.log.seek(0)
        why = self.log.read()
        self.log.close()
        raise RuntimeError("hapticd did not start: " + why)

    def _answers(self):
        end = time.monotonic() + 20.0
        while time.monotonic() < end and self.proc.poll() is None:
            try:
                with hc.Client.connect("127.0.0.1", self.port, timeout=0.5) as c:
                    if c.status()["ticks"] > 0:
                        return True
            except hc.HapticdError:
                time.sleep(0.05)
        return False

    def stop(self):
        self._end()
        self.log.close()

    def _end(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()

    def client(self, **kw):
        return hc.Client.connect("127.0.0.1", self.port, timeout=3.0, **kw)


class PoseStreams(unittest.TestCase):
    """The stream reader and sampler on their own (no daemon)."""

    def test_samples_lerp_slerp_and_segment_velocities(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "s.csv")
            with open(path, "w") as f:
                f.write("t,px,py,pz,qx,qy,qz,qw,buttons\n# a comment\n\n"
                        "0,0,0,0,0,0,0,1,1\n"
                        "0.5,0.1,0.2,0,0,0,0.7071067811865476,0.7071067811865476,2\n"
                        "1.0,0.1,0.2,0,0,0,-1,0\n")  # 180 deg written as -(0,0,1,0), no buttons
            rows = hc.read_pose_stream(path)
        self.assertEqual(len(rows), 3)
        self.assertEqual(rows[2][3], 0)
        t, p, q, v, w, buttons = hc.sample_pose_stream(rows, 0.25)
        for got, want in zip(p, (0.05, 0.1, 0.0)):
            self.assertAlmostEqual(got, want, places=15)
        for got, want in zip(q, (0, 0, math.sin(math.pi / 8), math.cos(math.pi / 8))):
            self.assertAlmostEqual(got, want, places=12)
        for got, want in zip(v, (0.2, 0.4, 0.0)):
            self.assertAlmostEqual(got, want, places=12)
        self.assertAlmostEqual(w[2], (math.pi / 2) / 0.5, places=9)
        self.assertEqual(buttons, 1)
        # the second segment turns the short way, 90 deg more about +z
        t, p, q, v, w, buttons = hc.sample_pose_stream(rows, 0.75)
        self.assertAlmostEqual(abs(q[2]), math.sin(3 * math.pi / 8), places=12)
        self.assertAlmostEqual(w[2], (math.pi / 2) / 0.5, places=9)
        self.assertEqual(buttons, 2)
        # before the first row and after the last: the end rows, standing still
        self.assertEqual(hc.sample_pose_stream(rows, -1.0)[1], (0.0, 0.0, 0.0))
        self.assertEqual(hc.sample_pose_stream(rows, 2.0)[3], (0.0, 0.0, 0.0))

    def test_bad_rows_are_named_by_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            for text, what in (("0,0,0,0,0,0,0,1\n0,0,0,0,0,0,0,1\n", ":2: t 0 is not after 0"),
                               ("0,0,0,0,0,0,0.5,0.5\n", ":1: quaternion norm"),
                               ("0,0,0,0,0,0,1\n", ":1: 7 fields"),
                               ("# only a comment\n", ": no rows")):
                path = os.path.join(d, "bad.csv")
                with open(path, "w") as f:
                    f.write(text)
                with self.assertRaises(ValueError) as e:
                    hc.read_pose_stream(path)
                self.assertIn("bad.csv" + what, str(e.exception))


class AgainstTheDaemon(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon()

    @classmethod
    def tearDownClass(cls):
        cls.daemon.stop()

    def test_status(self):
        with self.daemon.client() as c:
            s = c.status()
        self.assertEqual(s["device"], "sim")
        self.assertGreater(s["ticks"], 0)
        self.assertEqual(s["tick_rate_hz"], 1000.0)
        self.assertGreaterEqual(s["sessions"], 1)
        self.assertIn("bad_mac", s["refused"])
        self.assertIn("contact forces", s["plan"])
        self.assertEqual(s["shm_name"], "")  # --shm ""
        self.assertEqual(s["loading"], "")  # protocol 1.2: no scene build runs

    def test_states_carry_poses_forces_and_bodies(self):
        with self.daemon.client() as c:
            c.subscribe(200, bodies=True, contacts=True)
            states = list(c.states(0.5))
        self.assertGreater(len(states), 10)
        ticks = [s["tick"] for s in states]
        self.assertEqual(ticks, sorted(ticks))
        for s in states:
            for pose in (s["device"], s["proxy"]):
                self.assertAlmostEqual(sum(c * c for c in pose["q"]), 1.0, places=6)
            self.assertEqual(len(s["force_n"]), 3)
            self.assertEqual(len(s["contacts"]), min(s["contact_count"], 32))
            self.assertGreaterEqual(s["max_penetration_m"], 0.0)
        self.assertTrue(any(s["bodies"] for s in states))  # the demo's moving bodies

    def test_arm_and_poses_move_the_hand_to_the_target(self):
        with self.daemon.client() as c:
            c.subscribe(100)
            start = c.receive_state(2.0)
            self.assertIsNotNone(start)
            target = tuple(x + d for x, d in zip(start["device"]["p"], (0.0, 0.005, 0.0)))
            c.arm()
            end = time.monotonic() + 0.6
            sent = []
            while time.monotonic() < end:  # the gate holds a target 20 ms: keep it coming
                sent.append(c.pose(target))
                c.receive_state(0.005)
            last = None
            for s in c.states(0.1):
                last = s
        self.assertIsNotNone(last)
        self.assertIn(last["last_command_sequence"], sent)
        error = math.dist(last["device"]["p"], target)
        self.assertLess(error, 0.5 * 0.005, f"device {last['device']['p']} target {target}")
        self.assertTrue(last["armed"])

    def test_replay_sends_every_sample_and_the_gate_takes_them(self):
        with tempfile.TemporaryDirectory() as d, self.daemon.client() as c:
            c.subscribe(10)
            here = c.receive_state(2.0)["device"]["p"]
            path = os.path.join(d, "stream.csv")
            with open(path, "w") as f:
                f.write(f"0,{here[0]},{here[1]},{here[2]},0,0,0,1,0\n"
                        f"0.2,{here[0]},{here[1] + 0.002},{here[2]},0,0,0,1,0\n")
            before = c.status()["commands_accepted"]
            sent = c.replay(path, rate_hz=100)
            self.assertEqual(sent, 21)  # t = 0, 0.01, ..., 0.2
            deadline = time.monotonic() + 3.0
            while c.status()["commands_accepted"] < before + sent and time.monotonic() < deadline:
                time.sleep(0.02)
            self.assertEqual(c.status()["commands_accepted"] - before, sent)

    def test_scene_edit_refused_with_the_daemons_reason(self):
        with self.daemon.client() as c:
            with self.assertRaises(hc.Refused) as e:
                c.move(999, (0.0, 0.0, 0.0))
        self.assertEqual(e.exception.code, "bad_value")
        self.assertIn("999", str(e.exception))

    def test_load_accepts_a_scene_and_refuses_garbage(self):
        with self.daemon.client() as c:
            acked = []
            c.load(os.path.join(SOURCE, "scenes", "gears.glb"),
                   progress=lambda done, total: acked.append((done, total)))
            self.assertEqual(c.status()["scene"], "gears.glb")
            self.assertEqual(acked[-1][0], acked[-1][1])
            with self.assertRaises(hc.Refused) as e:
                c.load(b"not a glTF file at all", name="bad.glb")
            self.assertIn("scene refused", str(e.exception))
            self.assertEqual(c.status()["scene"], "gears.glb")  # the old scene stays
            c.load(os.path.join(SOURCE, "scenes", "peg_in_hole.glb"))
            self.assertEqual(c.status()["scene"], "peg_in_hole.glb")

    def test_the_example_records_two_seconds_of_states(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "states.csv")
            run = subprocess.run(
                [sys.executable, os.path.join(SOURCE, "client", "python", "examples",
                                              "record_states.py"), out,
                 "--port", str(self.daemon.port)],
                capture_output=True, text=True, timeout=60,
                env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
            self.assertEqual(run.returncode, 0, run.stderr)
            self.assertIn("recorded ", run.stdout)
            with open(out) as f:
                lines = f.read().splitlines()
        self.assertEqual(lines[0].split(","), hc.RECORD_COLUMNS)
        rows = [line.split(",") for line in lines[1:]]
        self.assertGreater(len(rows), 200)  # 2 s of a 1 kHz servo
        self.assertTrue(all(len(r) == len(hc.RECORD_COLUMNS) for r in rows))
        ticks = [int(r[0]) for r in rows]
        self.assertTrue(all(b > a for a, b in zip(ticks, ticks[1:])), "ticks in order, once each")
        times = [float(r[1]) for r in rows]
        self.assertTrue(all(b > a for a, b in zip(times, times[1:])))


class Edges(unittest.TestCase):
    def test_no_daemon_fails_at_once_on_port_unreachable(self):
        with self.assertRaises(hc.NoDaemon) as e:
            hc.Client.connect("127.0.0.1", closed_port(), timeout=60.0)
        self.assertIn("the port is unreachable", str(e.exception))

    def test_a_wrong_key_is_reported_as_a_wrong_key(self):
        with tempfile.TemporaryDirectory() as d:
            key = os.urandom(32)
            key_file = os.path.join(d, "key")
            with open(key_file, "w") as f:
                f.write(key.hex() + "\n")
            config = os.path.join(d, "hapticd.toml")
            with open(config, "w") as f:
                f.write(f'[network]\nkey_file = "{key_file}"\n')
            daemon = Daemon("--config", config)
            try:
                with self.assertRaises(hc.WrongKey) as e:
                    hc.Client.connect("127.0.0.1", daemon.port, key=os.urandom(32), timeout=0.5)
                self.assertIn("wrong key", str(e.exception))
                with hc.Client.connect("127.0.0.1", daemon.port, key=hc.load_key(key_file)) as c:
                    self.assertTrue(c.welcome["flags"] & hc.WELCOME_AUTHENTICATED)
                    c.arm()
                    c.disarm()
                with daemon.client() as watcher:  # no key: watch only
                    self.assertGreater(watcher.status()["ticks"], 0)
                    with self.assertRaises(hc.Refused) as r:
                        watcher.arm()
                    self.assertEqual(r.exception.code, "no_mac")
            finally:
                daemon.stop()


if __name__ == "__main__":
    unittest.main()
