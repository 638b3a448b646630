"""A Python client of hapticd's UDP protocol (version 1.1), standard library only.

Drive a running hapticd without a compiler: ask its status, load a scene, arm, send pose commands,
replay a pose-stream CSV, subscribe to its states. The byte layouts are protocol/README.md's (this
module is written from it); every field is little-endian, every pose is metres in scene
coordinates with a glTF-order quaternion (x, y, z, w).

    from hapticd_client import Client
    with Client.connect("127.0.0.1", 47100) as c:
        print(c.status()["device"])
        c.arm()
        c.pose((0.0, 0.01, 0.0))                 # one pose command (the gate holds it 20 ms)
        c.subscribe(100)
        for state in c.states(seconds=1.0):
            print(state["tick"], state["force_n"])

Errors are exceptions: NoDaemon (nothing answers; at once when the port is unreachable),
WrongKey (the daemon runs but drops datagrams tagged with this key), Refused (the daemon said no,
with its reason). A Client is used from one thread.
"""

import csv
import hashlib
import hmac
import math
import os
import socket
import struct
import time

__all__ = ["Client", "HapticdError", "NoDaemon", "WrongKey", "Refused", "read_pose_stream",
           "sample_pose_stream", "RECORD_COLUMNS", "record_row", "load_key"]

VERSION_MAJOR = 1
VERSION_MINOR = 2
MAGIC = 0x43545048
FLAG_MAC = 1
MAC_SIZE = 32
DEFAULT_PORT = 47100

# message types (protocol/README.md "Messages")
HELLO, WELCOME, SCENE_BEGIN, SCENE_CHUNK, SCENE_CHUNK_ACK, SCENE_COMMIT, SCENE_STATUS = range(1, 8)
SCENE_UPDATE, POSE_COMMAND, SUBSCRIBE, STATE, ARM, DISARM, HEARTBEAT, ERROR = range(8, 16)
STATUS_REQUEST, STATUS_REPLY, ACK, BYE = range(16, 20)

# refusal codes (Errc), by value
ERRC_NAMES = ["ok", "too_short", "too_long", "bad_magic", "bad_major", "bad_flags", "unknown_type",
              "bad_payload_length", "not_finite", "bad_value", "no_mac", "bad_mac", "replay",
              "rate_limited", "unknown_session", "wrong_peer", "server_full", "upload_error",
              "not_expected", "buffer_too_small"]

# Subscribe flags, Welcome flags, State fault and state bits
SUBSCRIBE_BODIES, SUBSCRIBE_CONTACTS, SUBSCRIBE_EACH_TICK = 1, 2, 4
WELCOME_KEY_REQUIRED, WELCOME_AUTHENTICATED = 1, 2
FAULT_NAMES = ["stream_lost", "device", "force_clamped", "not_finite", "tick_overrun"]
STATE_ARMED, STATE_STREAMING, STATE_RAMPING = 1, 2, 4
STATE_CONTACTS_TRUNCATED, STATE_BODIES_TRUNCATED = 8, 16

# SceneStatus codes
SCENE_ACCEPTED, SCENE_REFUSED, SCENE_INCOMPLETE, SCENE_VALIDATING, SCENE_UNKNOWN = range(5)

_HEADER = struct.Struct("<IBBHHHIQQQ")  # 40 bytes
_POSE = struct.Struct("<7d")            # p x, y, z; q x, y, z, w
_BODY_POSE = struct.Struct("<II7d")     # body_index, reserved, pose
_CONTACT = struct.Struct("<7d")         # p_W, n_W, depth_m
_STATE_FIXED = struct.Struct("<QQ7d7d3d3ddQQIIIIIIHHI")  # 232 bytes
_STATE_MINOR1 = struct.Struct("<IIdII")                 # 24 bytes
_STATUS_FIXED = struct.Struct("<QQQddIIIIIIIIQQQQHHHH")  # 112 bytes
_STATUS_MINOR1 = struct.Struct("<QQQQQQIHH")             # 56 bytes
_STATUS_MINOR2 = struct.Struct("<HH")                    # 4 bytes: loading_length, reserved
_WELCOME = struct.Struct("<QIIIIQIIHHHHQ")               # 56 bytes
_ERROR_FIXED = struct.Struct("<QHHHH")                   # 16 bytes
_SCENE_STATUS_FIXED = struct.Struct("<IHHQQHHI")         # 32 bytes

# the daemon's --record columns (docs/architecture.md "Records"); record_row() fills them
RECORD_COLUMNS = ("tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,"
                  "prx_qx,prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,"
                  "pairs_tested,pairs_skipped,tick_ns").split(",")


class HapticdError(Exception):
    """Anything that went wrong talking to hapticd; the message says what and where."""


class NoDaemon(HapticdError):
    """Nothing answered (the port is unreachable, or no answer within the timeout)."""


class WrongKey(HapticdError):
    """The daemon runs but drops every datagram tagged with this key."""


class Refused(HapticdError):
    """The daemon refused a request; `code` is the refusal's name (Errc), if any."""

    def __init__(self, message, code=""):
        super().__init__(message)
        self.code = code


def load_key(path):
    """The 32-byte pre-shared key from a file of 64 hex digits (the daemon's key_file)."""
    with open(path, encoding="ascii") as f:
        text = f.read().strip()
    if len(text) != 64:
        raise ValueError(f"{path}: a key is 64 hex digits, got {len(text)} characters")
    return bytes.fromhex(text)


def _tag(key, data):
    # crypto_auth (libsodium): HMAC-SHA-512 truncated to 32 bytes
    return hmac.new(key, data, hashlib.sha512).digest()[:MAC_SIZE]


def _pose_bytes(p, q):
    return _POSE.pack(*p, *q)


def _unit(q):
    n = math.sqrt(sum(c * c for c in q))
    if not n > 1e-12 or not math.isfinite(n):
        raise ValueError(f"quaternion {tuple(q)} is zero or not finite")
    return tuple(c / n for c in q)


# ---- decoders of what the server sends -----------------------------------------------------

def _decode_state(payload, minor):
    f = _STATE_FIXED.unpack_from(payload, 0)
    s = {"tick": f[0], "t": f[1] * 1e-9, "sim_time_ns": f[1],
         "device": {"p": f[2:5], "q": f[5:9]}, "proxy": {"p": f[9:12], "q": f[12:16]},
         "force_n": f[16:19], "torque_nm": f[19:22], "force_scale": f[22],
         "last_command_sequence": f[23], "tick_misses": f[24],
         "tick_p50_ns": f[25], "tick_p99_ns": f[26], "tick_max_ns": f[27],
         "fault_bits": f[28], "state_flags": f[29], "contact_count": f[30]}
    s["faults"] = [n for i, n in enumerate(FAULT_NAMES) if f[28] >> i & 1]
    s["armed"] = bool(f[29] & STATE_ARMED)
    n_contacts, n_bodies = f[31], f[32]
    at = _STATE_FIXED.size
    s["contacts"] = []
    for _ in range(n_contacts):
        c = _CONTACT.unpack_from(payload, at)
        s["contacts"].append({"p": c[0:3], "n": c[3:6], "depth_m": c[6]})
        at += _CONTACT.size
    s["bodies"] = []
    for _ in range(n_bodies):
        b = _BODY_POSE.unpack_from(payload, at)
        s["bodies"].append({"body": b[0], "p": b[2:5], "q": b[5:9]})
        at += _BODY_POSE.size
    tail = _STATE_MINOR1.unpack_from(payload, at) if minor >= 1 else (0, 0, 0.0, 0, 0)
    s.update(pairs_tested=tail[0], pairs_skipped=tail[1], max_penetration_m=tail[2],
             tick_ns=tail[3])
    return s


def _decode_status(payload, minor):
    f = _STATUS_FIXED.unpack_from(payload, 0)
    keys = ("uptime_ns ticks tick_misses tick_rate_hz measured_tick_hz tick_p50_ns tick_p99_ns "
            "tick_max_ns fault_bits state_flags sessions subscribers state_rate_hz "
            "packets_received packets_sent commands_accepted commands_dropped").split()
    r = dict(zip(keys, f))
    n_refused, n_device, n_scene, n_plan = f[17:21]
    at = _STATUS_FIXED.size
    counts = struct.unpack_from(f"<{n_refused}Q", payload, at)
    at += 8 * n_refused
    r["refused"] = {ERRC_NAMES[i] if i < len(ERRC_NAMES) else str(i): n
                    for i, n in enumerate(counts) if i > 0}
    for name, n in (("device", n_device), ("scene", n_scene), ("plan", n_plan)):
        r[name] = payload[at:at + n].decode("utf-8", "replace")
        at += n
    r["faults"] = [n for i, n in enumerate(FAULT_NAMES) if r["fault_bits"] >> i & 1]
    r["armed"] = bool(r["state_flags"] & STATE_ARMED)
    if minor >= 1:
        t = _STATUS_MINOR1.unpack_from(payload, at)
        r.update(shm_commands=t[0], shm_commands_refused=t[1], edit_batches_applied=t[2],
                 edit_batches_dropped=t[3], edits_applied=t[4], edits_refused=t[5],
                 shm_flags=t[6])
        at += _STATUS_MINOR1.size
        r["shm_name"] = payload[at:at + t[7]].decode("utf-8", "replace")
        at += t[7]
    r["loading"] = ""
    if minor >= 2:
        n_loading, _ = _STATUS_MINOR2.unpack_from(payload, at)
        at += _STATUS_MINOR2.size
        r["loading"] = payload[at:at + n_loading].decode("utf-8", "replace")
    return r


def _decode_error(payload):
    ref_sequence, ref_type, code, n, _ = _ERROR_FIXED.unpack_from(payload, 0)
    text = payload[_ERROR_FIXED.size:_ERROR_FIXED.size + n].decode("utf-8", "replace")
    name = ERRC_NAMES[code] if code < len(ERRC_NAMES) else f"code {code}"
    return {"ref_sequence": ref_sequence, "ref_type": ref_type, "code": name, "text": text}


def _decode_scene_status(payload):
    upload_id, status, n_missing, received, total, n_text, _, _ = \
        _SCENE_STATUS_FIXED.unpack_from(payload, 0)
    at = _SCENE_STATUS_FIXED.size
    missing = [struct.unpack_from("<QQ", payload, at + 16 * i) for i in range(n_missing)]
    at += 16 * n_missing
    return {"upload_id": upload_id, "status": status, "missing": missing, "received": received,
            "total": total, "text": payload[at:at + n_text].decode("utf-8", "replace")}


def _decode_welcome(payload):
    keys = ("session_id capabilities flags max_datagram_bytes max_chunk_bytes max_scene_bytes "
            "max_state_rate_hz tick_rate_hz max_state_contacts max_state_bodies "
            "max_update_entries reserved session_timeout_ns").split()
    return dict(zip(keys, _WELCOME.unpack_from(payload, 0)))


_DECODERS = {
    WELCOME: lambda p, minor: _decode_welcome(p),
    STATE: _decode_state,
    STATUS_REPLY: _decode_status,
    ERROR: lambda p, minor: _decode_error(p),
    SCENE_STATUS: lambda p, minor: _decode_scene_status(p),
    SCENE_CHUNK_ACK: lambda p, minor: dict(zip(("upload_id", "length", "offset", "received",
                                                "total"), struct.unpack_from("<IIQQQ", p, 0))),
    ACK: lambda p, minor: dict(zip(("ref_sequence", "ref_type"), struct.unpack_from("<QH", p, 0))),
    HEARTBEAT: lambda p, minor: {"echo_timestamp_ns": struct.unpack_from("<Q", p, 0)[0]},
    BYE: lambda p, minor: {},
}


class Client:
    """One session with hapticd over UDP. Make it with Client.connect(); close() (or a with
    block) ends the session. A session silent for 10 s is dropped by the daemon: every wait in
    this class sends a heartbeat when nothing was sent for a second."""

    def __init__(self, sock, server, key, timeout, name):
        self._sock = sock
        self._server = server
        self._key = key
        self._timeout = timeout
        self._name = name
        self._session = 0
        self._sequence = 0
        self._last_send = 0.0
        self._states = []
        self.welcome = {}

    # ---- the session ----

    @classmethod
    def connect(cls, host="127.0.0.1", port=DEFAULT_PORT, key=None, timeout=2.0,
                name="python"):
        """Opens a session: hello until welcome, resent every 0.1 s for `timeout` seconds.
        `key`: the 32-byte pre-shared key (load_key()), or None. Raises NoDaemon (at once when
        the port is unreachable), WrongKey, or Refused."""
        where = f"{host}:{port}"
        info = socket.getaddrinfo(host, port, 0, socket.SOCK_DGRAM)
        info.sort(key=lambda i: i[0] != socket.AF_INET)  # IPv4 first, as hapticctl does
        family, _, _, _, address = info[0]
        sock = socket.socket(family, socket.SOCK_DGRAM)
        sock.connect(address)  # a closed port is then reported (ECONNREFUSED) rather than silent
        c = cls(sock, where, key, timeout, name)
        try:
            hello = c._datagram(HELLO, struct.pack("<IHH", 1 | (4 if key else 0),
                                                   len(name.encode()), 0) + name.encode())
            answer = c._exchange(lambda: c._send_bytes(hello),
                                 lambda t, m: t in (WELCOME, ERROR))
            if answer is None:
                raise c._silence(address, family)
            kind, body = answer
            if kind == ERROR:
                raise Refused(f"{where} refused hello: {body['code']}: {body['text']}",
                              body["code"])
            c.welcome = body
            c._session = body["session_id"]
            return c
        except BaseException:
            sock.close()
            raise

    def close(self):
        """Ends the session (Bye) and closes the socket."""
        if self._session:
            try:
                self._send(BYE, b"")
            except OSError:
                pass
            self._session = 0
        self._sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---- requests ----

    def status(self):
        """The daemon's status as a dict: device, scene, plan, ticks, tick_rate_hz,
        measured_tick_hz, tick_p50_ns/p99/max, faults, armed, sessions, subscribers, packets,
        commands_accepted/dropped, refused (by name), shm and scene-edit counters."""
        return self._call(STATUS_REQUEST, b"", "status", lambda t, m: t == STATUS_REPLY)

    def arm(self):
        """Takes control and enables forces (clears a latched fault)."""
        self._request(ARM, b"", "arm")

    def disarm(self):
        """Ramps the force to zero over the daemon's [servo] stop_ramp_s."""
        self._request(DISARM, b"", "disarm")

    def subscribe(self, rate_hz, bodies=False, contacts=False, each_tick=False):
        """States at rate_hz (0 stops; at most 1000); with the body poses, the contacts, and
        each_tick: every tick the daemon's network thread sees, once."""
        flags = ((SUBSCRIBE_BODIES if bodies else 0) | (SUBSCRIBE_CONTACTS if contacts else 0) |
                 (SUBSCRIBE_EACH_TICK if each_tick else 0))
        self._request(SUBSCRIBE, struct.pack("<II", int(rate_hz), flags), "subscribe")

    def pose(self, p, q=(0.0, 0.0, 0.0, 1.0), v=(0.0, 0.0, 0.0), w=(0.0, 0.0, 0.0), buttons=0):
        """Sends one pose command: the target of the held body's origin (metres, scene frame;
        q normalised), its velocity (m/s) and angular velocity (rad/s). Returns its sequence
        number (the state's last_command_sequence shows it taken). The daemon's gate takes the
        commands of the session that armed last, holds a target 20 ms and ramps the force to
        zero by 200 ms without a newer one: stream poses (or replay()) to keep control."""
        values = (*p, *q, *v, *w)
        if len(values) != 13 or not all(math.isfinite(x) for x in values):
            raise ValueError("pose: p, v, w three finite numbers each, q four")
        payload = _pose_bytes(p, _unit(q)) + struct.pack("<3d3dII", *v, *w, buttons, 0)
        return self._send(POSE_COMMAND, payload)

    def move(self, body, p, q=(0.0, 0.0, 0.0, 1.0)):
        """Sets a kinematic body's pose (one SceneUpdate); Refused with the daemon's reason."""
        self._scene_update(poses=[(body, p, q)])

    def add(self, body, p, q=(0.0, 0.0, 0.0, 1.0)):
        """Makes an inactive body active at a pose."""
        self._scene_update(added=[(body, p, q)])

    def remove(self, body):
        """Makes a body inactive."""
        self._scene_update(removed=[body])

    def load(self, scene, name=None, chunk_bytes=1200, progress=None):
        """Uploads a scene (.glb): `scene` is a path or the bytes. Returns when the daemon has
        accepted and swapped it in; Refused with the loader's first error otherwise.
        `progress(acked_bytes, total_bytes)` is called as chunks are acknowledged."""
        if not isinstance(scene, (bytes, bytearray)):
            name = name or os.path.basename(scene)
            with open(scene, "rb") as f:
                scene = f.read()
        name = (name or "scene.glb").encode()[:128]
        if not scene:
            raise ValueError("load: the scene is empty")
        chunk = max(1, min(chunk_bytes, self.welcome.get("max_chunk_bytes") or chunk_bytes))
        upload_id = (self._sequence & 0xffff) + 1
        begin = (struct.pack("<IIQ", upload_id, chunk, len(scene)) + hashlib.sha256(scene).digest()
                 + struct.pack("<HH", len(name), 0) + name)
        pending = {off: None for off in range(0, len(scene), chunk)}  # offset -> time sent
        acked = 0
        deadline = time.monotonic() + 120.0
        verdict = self._upload_step(SCENE_BEGIN, begin, upload_id, deadline)
        while True:
            if verdict is not None and verdict["status"] in (SCENE_ACCEPTED, SCENE_REFUSED,
                                                             SCENE_UNKNOWN):
                return self._upload_end(verdict)
            while pending:  # chunks, 64 in flight, resent after 50 ms
                now = time.monotonic()
                if now > deadline:
                    raise HapticdError(f"load: not finished within 120 s ({self._server})")
                for off in sorted(pending)[:64]:
                    if pending[off] is None or now - pending[off] > 0.05:
                        data = scene[off:off + chunk]
                        self._send(SCENE_CHUNK, struct.pack("<IIQ", upload_id, len(data), off)
                                   + data)
                        pending[off] = now
                for kind, body in self._drain(0.005):
                    if kind == SCENE_CHUNK_ACK and body["upload_id"] == upload_id and \
                            body["offset"] in pending:
                        del pending[body["offset"]]
                        acked += min(chunk, len(scene) - body["offset"])
                        if progress:
                            progress(acked, len(scene))
                    elif kind == SCENE_STATUS and body["upload_id"] == upload_id and \
                            body["status"] in (SCENE_REFUSED, SCENE_UNKNOWN):
                        return self._upload_end(body)
            verdict = self._upload_step(SCENE_COMMIT, struct.pack("<II", upload_id, 0),
                                        upload_id, deadline)
            if verdict["status"] == SCENE_INCOMPLETE:
                for off, length in verdict["missing"]:
                    for o in range(off - off % chunk, off + length, chunk):
                        if o not in pending:
                            acked -= min(chunk, len(scene) - o)
                        pending[o] = None

    def receive_state(self, timeout=1.0):
        """The oldest state received and not taken yet, waiting up to `timeout` seconds; None
        when none came. States are dicts: tick, t (s), sim_time_ns, device and proxy ({p, q}),
        force_n, torque_nm, force_scale, last_command_sequence, tick figures, faults, armed,
        contact_count, contacts ([{p, n, depth_m}]), bodies ([{body, p, q}]), pairs_tested,
        pairs_skipped, max_penetration_m, tick_ns."""
        if not self._states:
            answer = self._wait(timeout, lambda t, m: t == STATE)
            if answer is not None:
                return answer[1]
        return self._states.pop(0) if self._states else None

    def states(self, seconds, timeout=2.0):
        """Yields the states that arrive during `seconds` (after subscribe()); raises NoDaemon
        when none comes for `timeout` seconds."""
        end = time.monotonic() + seconds
        last = time.monotonic()
        while time.monotonic() < end:
            s = self.receive_state(min(0.2, max(0.0, end - time.monotonic())))
            if s is not None:
                last = time.monotonic()
                yield s
            elif time.monotonic() - last > timeout:
                raise NoDaemon(f"no state from {self._server} for {timeout} s")

    def replay(self, path, rate_hz=None, arm=True):
        """Sends the pose stream CSV at `path` (t,px,py,pz,qx,qy,qz,qw[,buttons]) as pose
        commands: sampled at t0 + k/rate_hz (lerp, shortest-arc slerp, buttons of the row at or
        before; default rate: the daemon's tick rate) and sent at those times on the wall clock.
        Returns the number of commands sent."""
        rows = read_pose_stream(path)
        rate = float(rate_hz or self.welcome.get("tick_rate_hz") or 1000)
        if not rate > 0:
            raise ValueError("replay: rate_hz must be > 0")
        if arm:
            self.arm()
        t0, duration = rows[0][0], rows[-1][0] - rows[0][0]
        times = [k / rate for k in range(int(math.floor(duration * rate + 1e-9)) + 1)]
        if times[-1] < duration - 1e-12:
            times.append(duration)
        start = time.monotonic()
        for ts in times:
            t, p, q, v, w, buttons = sample_pose_stream(rows, t0 + ts)
            delay = start + ts - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            self.pose(p, q, v, w, buttons)
            self._drain(0)
        return len(times)

    # ---- the wire ----

    def _datagram(self, kind, payload):
        self._sequence += 1
        flags = FLAG_MAC if self._key else 0
        header = _HEADER.pack(MAGIC, VERSION_MAJOR, VERSION_MINOR, kind, flags, 0, len(payload),
                              self._session, self._sequence, time.monotonic_ns())
        data = header + payload
        return data + _tag(self._key, data) if self._key else data

    def _send_bytes(self, data):
        self._last_send = time.monotonic()
        try:
            self._sock.send(data)
        except ConnectionRefusedError:
            raise self._unreachable() from None

    def _unreachable(self):
        return NoDaemon(f"no daemon at {self._server}: the port is unreachable (nothing listens "
                        f"there: is hapticd running?)")

    def _send(self, kind, payload):
        self._send_bytes(self._datagram(kind, payload))
        return self._sequence

    def _parse(self, data):
        """(type, body, header session) of a datagram, or None when it is not a good one."""
        if len(data) < _HEADER.size:
            return None
        magic, major, minor, kind, flags, _, length, session, _, _ = _HEADER.unpack_from(data)
        tagged = flags & FLAG_MAC
        if magic != MAGIC or major != VERSION_MAJOR or \
                len(data) != _HEADER.size + length + (MAC_SIZE if tagged else 0):
            return None
        if self._key and tagged and not hmac.compare_digest(
                data[-MAC_SIZE:], _tag(self._key, data[:-MAC_SIZE])):
            return None
        if self._key and not tagged and not (self._session == 0 and kind == ERROR):
            return None  # a keyed session takes only tagged datagrams
        decoder = _DECODERS.get(kind)
        if decoder is None:
            return None
        try:
            body = decoder(data[_HEADER.size:_HEADER.size + length], minor)
        except (struct.error, IndexError):
            return None
        if self._session and session != self._session:
            return None
        return kind, body

    def _drain(self, timeout):
        """Every message that arrives within `timeout` seconds (states are queued too)."""
        out = []
        answer = self._wait(timeout, lambda t, m: out.append((t, m)) and False)
        del answer
        return out

    def _wait(self, timeout, want):
        """Receives for up to `timeout` seconds; returns the first (type, body) that `want`
        takes. States that are not taken are queued for receive_state(); heartbeats go out
        when nothing was sent for a second."""
        end = time.monotonic() + timeout
        while True:
            if self._session and time.monotonic() - self._last_send > 1.0:
                self._send(HEARTBEAT, struct.pack("<Q", 0))
            left = end - time.monotonic()
            self._sock.settimeout(max(0.0, min(left, 0.25)))
            try:
                data = self._sock.recv(65536)
            except socket.timeout:
                if time.monotonic() >= end:
                    return None
                continue
            except BlockingIOError:
                return None
            except ConnectionRefusedError:
                raise self._unreachable() from None
            parsed = self._parse(data)
            if parsed is None:
                continue
            if want(*parsed):
                return parsed
            if parsed[0] == STATE:
                self._states.append(parsed[1])

    def _exchange(self, send_once, want):
        """send_once() every 0.1 s until `want` takes an answer (returned) or the timeout."""
        end = time.monotonic() + self._timeout
        while time.monotonic() < end:
            send_once()
            answer = self._wait(0.1, want)
            if answer is not None:
                return answer
        return None

    def _call(self, kind, payload, what, answers):
        sent = []

        def want(t, m):
            return (t == ERROR and m["ref_sequence"] in sent) or answers(t, m) and \
                (t != ACK or m["ref_sequence"] in sent)

        answer = self._exchange(lambda: sent.append(self._send(kind, payload)), want)
        if answer is None:
            raise NoDaemon(f"{what}: no answer from {self._server} within {self._timeout} s")
        if answer[0] == ERROR:
            raise Refused(f"{what} refused: {answer[1]['code']}: {answer[1]['text']}",
                          answer[1]["code"])
        return answer[1]

    def _request(self, kind, payload, what):
        self._call(kind, payload, what, lambda t, m: t == ACK and m["ref_type"] == kind)

    def _scene_update(self, poses=(), added=(), removed=()):
        payload = struct.pack("<HHHH", len(poses), len(added), len(removed), 0)
        for body, p, q in (*poses, *added):
            payload += struct.pack("<II", body, 0) + _pose_bytes(p, _unit(q))
        payload += b"".join(struct.pack("<I", b) for b in removed)
        self._request(SCENE_UPDATE, payload, "scene update")

    def _upload_step(self, kind, payload, upload_id, deadline):
        """Sends begin or commit every 0.1 s until a SceneStatus of this upload (or an Error
        about the upload) comes; returns that status as a dict."""
        while time.monotonic() < deadline:
            self._send(kind, payload)
            answer = self._wait(0.1, lambda t, m: (t == SCENE_STATUS and m["upload_id"] ==
                                                   upload_id) or (t == ERROR and m["ref_type"]
                                                   in (SCENE_BEGIN, SCENE_CHUNK, SCENE_COMMIT)))
            if answer is None:
                continue
            if answer[0] == ERROR:
                return {"status": SCENE_REFUSED,
                        "text": f"{answer[1]['code']}: {answer[1]['text']}", "missing": []}
            if answer[1]["status"] != SCENE_VALIDATING and not (
                    answer[1]["status"] == SCENE_INCOMPLETE and kind == SCENE_COMMIT and
                    not answer[1]["missing"]):
                return answer[1]
        raise HapticdError(f"load: not finished within 120 s ({self._server})")

    def _upload_end(self, verdict):
        if verdict["status"] == SCENE_ACCEPTED:
            return None
        raise Refused(f"scene refused: {verdict['text']}", "upload")

    def _silence(self, address, family):
        """The error for a hello nobody answered: a keyed daemon drops a wrong tag without a
        word, so a keyed client asks once more without a tag from another port."""
        waited = (f"no daemon at {self._server}: no answer within {self._timeout} s")
        if not self._key:
            return NoDaemon(waited + " (is hapticd running?)")
        probe = socket.socket(family, socket.SOCK_DGRAM)
        try:
            probe.connect(address)
            hello = _HEADER.pack(MAGIC, VERSION_MAJOR, VERSION_MINOR, HELLO, 0, 0, 8, 0, 1,
                                 time.monotonic_ns()) + struct.pack("<IHH", 1, 0, 0)
            end = time.monotonic() + min(self._timeout, 1.0)
            while time.monotonic() < end:
                probe.send(hello)
                probe.settimeout(0.1)
                try:
                    data = probe.recv(65536)
                except socket.timeout:
                    continue
                if len(data) >= _HEADER.size + _WELCOME.size and \
                        _HEADER.unpack_from(data)[3] == WELCOME:
                    welcome = _decode_welcome(data[_HEADER.size:])
                    probe.send(_HEADER.pack(MAGIC, VERSION_MAJOR, VERSION_MINOR, BYE, 0, 0, 0,
                                            welcome["session_id"], 2, time.monotonic_ns()))
                    if welcome["flags"] & WELCOME_KEY_REQUIRED:
                        return WrongKey(f"wrong key: hapticd at {self._server} answers, but "
                                        f"drops every datagram tagged with this key")
                    break
        except OSError:
            pass
        finally:
            probe.close()
        return NoDaemon(waited + " (is hapticd running? A daemon with another key drops "
                        "datagrams tagged with this one without a word: the key may also be "
                        "wrong)")


# ---- pose streams and records ----------------------------------------------------------------

def read_pose_stream(path):
    """The rows of a pose-stream CSV as (t, (px, py, pz), (qx, qy, qz, qw), buttons), in the
    lenient form hapticctl replay reads: '#' comments and blank lines skipped, an optional
    header, 8 or 9 fields a row (buttons 0 when absent), t strictly increasing, quaternions
    normalised (a norm off 1 by more than 1e-3 is refused). Raises ValueError naming
    FILE:LINE."""
    rows = []
    with open(path, newline="", encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            text = line.split("#", 1)[0].strip()
            if not text or text.startswith("t,"):
                continue
            fields = [x.strip() for x in text.split(",")]
            try:
                if len(fields) not in (8, 9):
                    raise ValueError(f"{len(fields)} fields, expected 8 or 9")
                values = [float(x) for x in fields[:8]]
                buttons = int(fields[8]) if len(fields) == 9 else 0
                if not all(math.isfinite(x) for x in values):
                    raise ValueError("a number is not finite")
                q = values[4:8]
                norm = math.sqrt(sum(c * c for c in q))
                if abs(norm - 1.0) > 1e-3:
                    raise ValueError(f"quaternion norm {norm:.6g} is not 1")
                if rows and values[0] <= rows[-1][0]:
                    raise ValueError(f"t {values[0]:g} is not after {rows[-1][0]:g}")
            except ValueError as e:
                raise ValueError(f"{path}:{number}: {e}") from None
            rows.append((values[0], tuple(values[1:4]), tuple(c / norm for c in q), buttons))
    if not rows:
        raise ValueError(f"{path}: no rows")
    return rows


def _slerp(a, b, s):
    d = sum(x * y for x, y in zip(a, b))
    if d < 0.0:  # the shorter arc
        b, d = tuple(-x for x in b), -d
    if d > 0.9995:
        q = tuple(x + s * (y - x) for x, y in zip(a, b))
    else:
        theta = math.acos(d)
        wa, wb = math.sin((1 - s) * theta), math.sin(s * theta)
        q = tuple((wa * x + wb * y) / math.sin(theta) for x, y in zip(a, b))
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


def _rotation_vector(q):
    x, y, z, w = q if q[3] >= 0 else tuple(-c for c in q)
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return (2 * x, 2 * y, 2 * z)
    angle = 2 * math.atan2(s, w)
    return (x / s * angle, y / s * angle, z / s * angle)


def sample_pose_stream(rows, t):
    """The stream at time t: (t, p, q, v, w, buttons); before the first row the first, after the
    last the last (velocities 0 there), between rows lerp and slerp with the segment's linear and
    angular velocity."""
    if t <= rows[0][0] or len(rows) == 1:
        return (t, rows[0][1], rows[0][2], (0.0,) * 3, (0.0,) * 3, rows[0][3])
    if t >= rows[-1][0]:
        return (t, rows[-1][1], rows[-1][2], (0.0,) * 3, (0.0,) * 3, rows[-1][3])
    lo, hi = 0, len(rows) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if rows[mid][0] <= t else (lo, mid)
    (ta, pa, qa, buttons), (tb, pb, qb, _) = rows[lo], rows[hi]
    s, dt = (t - ta) / (tb - ta), tb - ta
    p = tuple(x + s * (y - x) for x, y in zip(pa, pb))
    v = tuple((y - x) / dt for x, y in zip(pa, pb))
    # rotation from a to b: qb * conj(qa)
    ax, ay, az, aw = -qa[0], -qa[1], -qa[2], qa[3]
    bx, by, bz, bw = qb
    rel = (bw * ax + bx * aw + by * az - bz * ay, bw * ay - bx * az + by * aw + bz * ax,
           bw * az + bx * ay - by * ax + bz * aw, bw * aw - bx * ax - by * ay - bz * az)
    w = tuple(c / dt for c in _rotation_vector(rel))
    return (t, p, _slerp(qa, qb, s), v, w, buttons)


def record_row(state):
    """The daemon's --record row (RECORD_COLUMNS) of a state: tick as the daemon's record numbers
    it (State tick - 1), t in seconds, poses, force, torque, contact count, max penetration,
    pairs tested and skipped, this tick's compute ns."""
    d, x = state["device"], state["proxy"]
    return [state["tick"] - 1, state["t"], *d["p"], *d["q"], *x["p"], *x["q"],
            *state["force_n"], *state["torque_nm"], state["contact_count"],
            state["max_penetration_m"], state["pairs_tested"], state["pairs_skipped"],
            state["tick_ns"]]


def write_record(path, states):
    """Writes states as the daemon's --record CSV (numbers as repr: shortest exact)."""
    with open(path, "w", newline="", encoding="ascii") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(RECORD_COLUMNS)
        for s in states:
            out.writerow(record_row(s))
