"""hapticd's WebSocket JSON API (protocol/websocket.md) end to end: the real hapticd binary as a
subprocess on free loopback ports (sim device, no shared memory, no real-time priority), driven by
client/python/hapticd_ws.py. Contents are asserted, never speed; every wait is bounded by a count
or a generous timeout that only ends a hung test.

Run by CTest (web.api) with HAPTICD and HAPTICD_SOURCE_DIR set; by hand:
    HAPTICD=build/release/bin/hapticd HAPTICD_SOURCE_DIR=. \\
        python3 -m unittest -v tests/web/test_web_api.py
"""

import base64
import http.client
import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import unittest

SOURCE = os.environ.get("HAPTICD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "../.."))
sys.path.insert(0, os.path.join(SOURCE, "client", "python"))
import hapticd_ws as ws  # noqa: E402

KEY = bytes(range(32))
STATE_FIELDS = {"type", "tick", "t", "device", "proxy", "force", "torque", "force_scale",
                "contact_count", "contacts", "bodies", "max_penetration", "pairs_tested",
                "pairs_skipped", "tick_ns", "tick_p50_ns", "tick_p99_ns", "tick_max_ns",
                "tick_misses", "faults", "armed", "streaming", "ramping", "last_sequence"}


def free_port(kind):
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scene_bytes(name):
    with open(os.path.join(SOURCE, "scenes", name), "rb") as f:
        return f.read()


class Daemon:
    """hapticd on free loopback ports (UDP and web); stop() sends SIGTERM and waits."""

    def __init__(self, config_text=None, *extra):
        binary = os.environ.get("HAPTICD")
        if not binary:
            raise unittest.SkipTest("HAPTICD (the hapticd binary) is not set")
        self.log = tempfile.TemporaryFile(mode="w+")
        self.config = None
        args = []
        if config_text is not None:
            self.config = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
            self.config.write(config_text)
            self.config.close()
            args = ["--config", self.config.name]
        for _ in range(3):  # another program may take a port between the probe and the bind
            self.port = free_port(socket.SOCK_STREAM)
            self.proc = subprocess.Popen(
                [binary, *args, "--udp", f"127.0.0.1:{free_port(socket.SOCK_DGRAM)}",
                 "--web", f"127.0.0.1:{self.port}", "--shm", "", "--realtime", "off", *extra],
                stdout=subprocess.DEVNULL, stderr=self.log)
            if self._answers():
                return
            self._end()
        self.log.seek(0)
        raise RuntimeError("hapticd did not start: " + self.log.read())

    def _answers(self):
        end = time.monotonic() + 30.0
        while time.monotonic() < end and self.proc.poll() is None:
            try:
                with self.client() as c:
                    if c.request({"type": "status"})["ticks"] > 0:
                        return True
            except (ws.WebError, OSError):
                time.sleep(0.05)
        return False

    def client(self, **kw):
        kw.setdefault("timeout", 10.0)
        return ws.WebClient.connect("127.0.0.1", self.port, **kw)

    def stop(self):
        self._end()
        self.log.close()
        if self.config:
            os.unlink(self.config.name)

    def _end(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


class Messages(unittest.TestCase):
    """Every message type against one daemon (the built-in demo scene, no key)."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon()

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_hello_and_welcome(self):
        with self.d.client(name="tester") as c:
            h = c.server_hello
            self.assertEqual(list(h)[0], "type")
            self.assertEqual(h["type"], "hello")
            self.assertEqual(len(h["nonce"]), 64)
            self.assertFalse(h["key_required"])
            self.assertEqual(h["tick_rate_hz"], 1000)
            self.assertEqual(c.welcome["type"], "welcome")
            self.assertEqual(c.welcome["name"], "tester")
            self.assertTrue(c.welcome["may_command"])

    def test_hello_first(self):
        with self.d.client(hello=False) as c:
            e = c.request({"type": "status"})
            self.assertEqual(e["type"], "error")
            self.assertIn("hello first", e["error"])

    def test_status(self):
        with self.d.client() as c:
            s = c.request({"type": "status"})
            self.assertEqual(s["type"], "status")
            self.assertEqual(s["device"], "sim")
            self.assertGreater(s["ticks"], 0)
            self.assertEqual(s["tick_rate_hz"], 1000.0)
            self.assertIsInstance(s["faults"], list)
            self.assertGreaterEqual(s["web"]["clients"], 1)
            self.assertIn("peg_in_hole", s["scene"])
            self.assertEqual(s["loading"], "")  # no scene build runs

    def test_subscribe_every_field_and_a_subset(self):
        with self.d.client() as c:
            a = c.request({"type": "subscribe", "rate_hz": 100})
            self.assertEqual(a, {"type": "ack", "ref": "subscribe", "rate_hz": 100})
            s1 = c.receive("state")
            self.assertEqual(set(s1), STATE_FIELDS)
            self.assertEqual(list(s1)[0], "type")
            self.assertEqual(len(s1["device"]["p"]), 3)
            self.assertEqual(len(s1["proxy"]["q"]), 4)
            self.assertEqual(len(s1["force"]), 3)
            self.assertEqual(len(s1["torque"]), 3)
            self.assertGreater(s1["tick_ns"], 0)
            self.assertGreater(len(s1["bodies"]), 0)  # the held handle at least
            s2 = c.receive("state")
            self.assertGreater(s2["tick"], s1["tick"])  # never the same tick twice
            c.request({"type": "subscribe", "rate_hz": 100, "fields": ["force", "contacts"]})
            while True:  # states already on their way have every field
                s = c.receive("state")
                if set(s) != STATE_FIELDS:
                    break
            self.assertEqual(set(s), {"type", "tick", "t", "force", "contacts"})
            e = c.request({"type": "subscribe", "rate_hz": 10, "fields": ["nosuch"]})
            self.assertEqual(e["type"], "error")
            self.assertIn("nosuch", e["error"])
            # above the tick rate: clamped to it
            self.assertEqual(c.request({"type": "subscribe", "rate_hz": 5000})["rate_hz"], 1000)
            self.assertEqual(c.request({"type": "subscribe", "rate_hz": 0})["rate_hz"], 0)

    def test_arm_pose_disarm(self):
        with self.d.client() as c:
            self.assertEqual(c.request({"type": "arm"}), {"type": "ack", "ref": "arm"})
            c.request({"type": "subscribe", "rate_hz": 200, "fields": ["device", "last_sequence",
                                                                      "streaming", "armed"]})
            start = c.receive("state")["device"]
            target = [start["p"][0], start["p"][1] + 0.002, start["p"][2]]
            # the arm took sequence 1; poses 2..201
            for _ in range(200):
                c.send({"type": "pose", "p": target, "q": start["q"]})
            seen = None
            for _ in range(2000):
                s = c.receive("state")
                if s["last_sequence"] == 201:
                    seen = s
                    break
            self.assertIsNotNone(seen, "the newest pose's sequence never showed in a state")
            self.assertTrue(seen["streaming"])
            self.assertTrue(seen["armed"])
            bad = c.request({"type": "pose", "p": [0, 0, 0], "q": [0, 0, 0, 2]}, "error")
            self.assertIn("length 2", bad["error"])
            bad = c.request({"type": "pose", "p": [0, "x", 0], "q": [0, 0, 0, 1]}, "error")
            self.assertIn("p[1]", bad["error"])
            self.assertEqual(c.request({"type": "disarm"}), {"type": "ack", "ref": "disarm"})

    def test_load_scene_and_edits(self):
        glb = scene_bytes("dynamic.glb")
        with self.d.client() as c:
            r = c.request({"type": "load", "name": "dynamic.glb",
                           "glb_base64": base64.b64encode(glb).decode()}, timeout=60)
            self.assertEqual(r, {"type": "loaded", "ok": True})
            sc = c.request({"type": "scene"})
            self.assertEqual(sc["name"], "dynamic.glb")
            self.assertEqual(base64.b64decode(sc["glb_base64"]), glb)  # the bytes it runs
            probes = [b for b in sc["bodies"] if b["probe"]]
            self.assertEqual(len(probes), 1)
            self.assertEqual(sc["probe_body"], probes[0]["index"])
            dyn = [b for b in sc["bodies"] if b["motion"] == "dynamic" and not b["probe"]]
            stat = [b for b in sc["bodies"] if b["motion"] == "static"]
            self.assertTrue(dyn and stat)
            body = dyn[0]["index"]
            self.assertEqual(c.request({"type": "remove", "body": body}),
                             {"type": "ack", "ref": "remove", "body": body})
            self.assertEqual(c.request({"type": "add", "body": body, "p": [0, 0.5, 0],
                                        "q": [0, 0, 0, 1]}),
                             {"type": "ack", "ref": "add", "body": body})
            e = c.request({"type": "move", "body": body, "p": [0, 0.5, 0], "q": [0, 0, 0, 1]})
            self.assertEqual(e["type"], "error")
            self.assertIn("not kinematic", e["error"])
            e = c.request({"type": "remove", "body": stat[0]["index"]})
            self.assertIn("static", e["error"])
            e = c.request({"type": "remove", "body": 100000})
            self.assertIn("does not exist", e["error"])
            # a bad scene: refused with the loader's first error, the old one stays
            r = c.request({"type": "load", "name": "bad.glb",
                           "glb_base64": base64.b64encode(b"glTF not really").decode()},
                          timeout=60)
            self.assertEqual(r["type"], "loaded")
            self.assertFalse(r["ok"])
            self.assertIn("bad.glb", r["error"])
            self.assertEqual(c.request({"type": "scene"})["name"], "dynamic.glb")
            e = c.request({"type": "load", "glb_base64": "%%%not base64"})
            self.assertEqual(e["type"], "error")
            # back to the demo the other tests expect
            r = c.request({"type": "load", "name": "peg_in_hole.glb",
                           "glb_base64": base64.b64encode(scene_bytes("peg_in_hole.glb"))
                           .decode()}, timeout=60)
            self.assertTrue(r["ok"])

    def test_malformed_messages_keep_the_connection(self):
        with self.d.client() as c:
            for text, what in [("{not json", "not JSON"), ("[1, 2]", "JSON object"),
                               ('{"name": "x"}', "\"type\""), ('{"type": 7}', "\"type\""),
                               ('{"type": "nosuch"}', "unknown type"),
                               ('{"type": "subscribe", "rate_hz": "fast"}', "rate_hz"),
                               ('{"type": "remove", "body": -1}', "body")]:
                c.send(text)
                e = c.receive(("error",))
                self.assertIn(what, e["error"], text)
            c.send_frame(0x2, b"\x01\x02")  # binary
            self.assertIn("binary", c.receive("error")["error"])
            self.assertEqual(c.request({"type": "status"})["type"], "status")

    def test_http_serves_the_viewer_and_nothing_else(self):
        conn = http.client.HTTPConnection("127.0.0.1", self.d.port, timeout=10)
        conn.request("GET", "/")
        r = conn.getresponse()
        body = r.read()
        self.assertEqual(r.status, 200)
        self.assertIn("text/html", r.getheader("Content-Type"))
        with open(os.path.join(SOURCE, "web", "index.html"), "rb") as f:
            self.assertEqual(body, f.read())
        for path, status in [("/../CMakeLists.txt", 400), ("/nosuch.html", 404),
                             ("/%2e%2e/CMakeLists.txt", 400)]:
            conn.request("GET", path)
            r = conn.getresponse()
            r.read()
            self.assertEqual(r.status, status, path)
        conn.close()


class Limits(unittest.TestCase):
    """The size bound, a slow reader, many clients (max_message_bytes 4096)."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("[web]\nmax_message_bytes = 4096\n")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_oversized_message_is_refused(self):
        with self.d.client() as c:
            c.send({"type": "status", "pad": "x" * 3000})  # under the bound: answered
            self.assertEqual(c.receive(("status", "error"))["type"], "status")
            c.send({"type": "status", "pad": "x" * 5000})
            with self.assertRaises(ws.WebError):
                c.receive("status")
            self.assertEqual(c.close_code, 1009)  # "message too big"
        with self.d.client() as c:  # the server serves on
            self.assertEqual(c.request({"type": "status"})["type"], "status")

    def test_slow_reader_does_not_slow_the_servo_loop(self):
        # a client that subscribes at the tick rate to every field and never reads
        slow = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        slow.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        slow.connect(("127.0.0.1", self.d.port))
        reader = ws.WebClient(slow)
        reader._handshake("127.0.0.1", self.d.port)
        reader.send({"type": "hello", "name": "slow"})
        reader.send({"type": "subscribe", "rate_hz": 1000})
        with self.d.client() as c:
            first = c.request({"type": "status"})
            replaced = 0
            for _ in range(600):  # until the server has replaced waiting states (bounded)
                s = c.request({"type": "status"})
                replaced = s["web"]["states_replaced"]
                if replaced > 100 and s["ticks"] > first["ticks"] + 2000:
                    break
                time.sleep(0.05)
            self.assertGreater(replaced, 100, "the slow reader never fell behind")
            # the loop kept ticking and never latched an overrun fault meanwhile
            self.assertGreater(s["ticks"], first["ticks"] + 2000)
            self.assertNotIn("tick_overrun", s["faults"])
            self.assertEqual(s["web"]["closed_slow"], 0)  # states never pile up: one waits
        slow.close()

    def test_fifty_clients_at_once(self):
        clients = [self.d.client(name=f"c{i}") for i in range(50)]
        try:
            for c in clients:
                c.send({"type": "subscribe", "rate_hz": 20, "fields": ["force"]})
            ticks = []
            for c in clients:
                self.assertEqual(c.receive("ack")["ref"], "subscribe")
                s = [c.receive("state") for _ in range(3)]
                self.assertLess(s[0]["tick"], s[1]["tick"])
                self.assertLess(s[1]["tick"], s[2]["tick"])
                ticks.append(s[2]["tick"])
            st = clients[0].request({"type": "status"})
            self.assertGreaterEqual(st["web"]["clients"], 50)
            self.assertGreaterEqual(st["web"]["subscribers"], 50)
        finally:
            for c in clients:
                c.close()


class Key(unittest.TestCase):
    """With [network] key_file: commands need the key's tag; watching does not."""

    @classmethod
    def setUpClass(cls):
        cls.key_file = tempfile.NamedTemporaryFile("w", suffix=".hex", delete=False)
        cls.key_file.write(KEY.hex() + "\n")
        cls.key_file.close()
        cls.d = Daemon(f'[network]\nkey_file = "{cls.key_file.name}"\n')

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()
        os.unlink(cls.key_file.name)

    def test_right_key_commands(self):
        with self.d.client(key=KEY) as c:
            self.assertTrue(c.server_hello["key_required"])
            self.assertTrue(c.welcome["authenticated"])
            self.assertEqual(c.request({"type": "arm"})["type"], "ack")
            self.assertEqual(c.request({"type": "disarm"})["type"], "ack")

    def test_wrong_key_is_refused(self):
        with self.d.client(key=bytes(32)) as c:
            self.assertEqual(c.welcome["type"], "error")
            self.assertIn("wrong key", c.welcome["error"])
            for m in [{"type": "arm"}, {"type": "pose", "p": [0, 0, 0], "q": [0, 0, 0, 1]},
                      {"type": "load", "glb_base64": ""}, {"type": "remove", "body": 1}]:
                e = c.request(m)
                self.assertEqual(e["type"], "error", m)
                self.assertIn("watches only", e["error"])
            self.assertEqual(c.request({"type": "status"})["type"], "status")

    def test_no_tag_watches_only(self):
        with self.d.client() as c:
            self.assertFalse(c.welcome["authenticated"])
            self.assertFalse(c.welcome["may_command"])
            self.assertIn("watches only", c.request({"type": "arm"})["error"])
            c.request({"type": "subscribe", "rate_hz": 50})
            self.assertEqual(c.receive("state")["type"], "state")


if __name__ == "__main__":
    unittest.main()
