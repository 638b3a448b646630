"""A Python client of hapticd's WebSocket JSON API (protocol/websocket.md), standard library only.

A minimal WebSocket client (RFC 6455: the handshake, masked text frames out, text, ping and close
frames in) and the API's hello with the key's tag. Every message is a dict with "type" first.

    from hapticd_ws import WebClient
    with WebClient.connect("127.0.0.1", 47180, name="notebook") as c:   # key=bytes when keyed
        print(c.request({"type": "status"})["ticks"])
        c.send({"type": "subscribe", "rate_hz": 50, "fields": ["device", "force"]})
        for _ in range(10):
            print(c.receive("state")["force"])

Errors are exceptions: WebError (no server, a broken handshake, the connection closed).
A WebClient is used from one thread.
"""

import base64
import hashlib
import hmac
import json
import os
import socket
import struct
import time

__all__ = ["WebClient", "WebError", "tag_of"]


class WebError(Exception):
    """The server is not there, the handshake failed, or the connection closed."""


def tag_of(key, nonce_hex):
    """The hello's tag: HMAC-SHA512-256 (HMAC-SHA-512 cut to 32 bytes) of the nonce, as hex."""
    return hmac.new(key, bytes.fromhex(nonce_hex), hashlib.sha512).digest()[:32].hex()


class WebClient:
    """One WebSocket connection to hapticd's /ws."""

    def __init__(self, sock):
        self.sock = sock
        self.buffer = b""
        self.pending = []  # messages read while waiting for another type
        self.server_hello = None
        self.welcome = None
        self.close_code = None

    @classmethod
    def connect(cls, host="127.0.0.1", port=47180, name="python", key=None, timeout=5.0,
                hello=True):
        """Opens /ws, reads the server's hello (its nonce) and, unless hello=False, sends ours
        (with the tag when `key`, 32 bytes, is given) and waits for the welcome."""
        try:
            sock = socket.create_connection((host, port), timeout=timeout)
        except OSError as e:
            raise WebError(f"no hapticd web endpoint at {host}:{port}: {e}") from e
        c = cls(sock)
        c._handshake(host, port)
        c.server_hello = c.receive("hello", timeout)
        if hello:
            m = {"type": "hello", "name": name}
            if key is not None:
                m["tag"] = tag_of(key, c.server_hello["nonce"])
            c.send(m)
            c.welcome = c.receive(("welcome", "error"), timeout)
        return c

    def _handshake(self, host, port):
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET /ws HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                           "Sec-WebSocket-Version: 13\r\n\r\n").encode())
        while b"\r\n\r\n" not in self.buffer:
            self._fill()
        head, self.buffer = self.buffer.split(b"\r\n\r\n", 1)
        lines = head.decode("latin-1").split("\r\n")
        if " 101 " not in lines[0] + " ":
            raise WebError("handshake refused: " + lines[0])
        accept = base64.b64encode(hashlib.sha1(
            (key + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11").encode()).digest()).decode()
        if not any(l.lower().startswith("sec-websocket-accept:") and l.split(":", 1)[1].strip()
                   == accept for l in lines[1:]):
            raise WebError("handshake: a wrong Sec-WebSocket-Accept")

    def _fill(self):
        data = self.sock.recv(65536)
        if not data:
            raise WebError("the server closed the connection")
        self.buffer += data

    def _take(self, n):
        while len(self.buffer) < n:
            self._fill()
        out, self.buffer = self.buffer[:n], self.buffer[n:]
        return out

    def send_frame(self, opcode, payload, fin=True, length=None):
        """One masked frame (length: the length to announce, for tests of the server's limit)."""
        n = len(payload) if length is None else length
        head = bytes([(0x80 if fin else 0) | opcode])
        if n < 126:
            head += bytes([0x80 | n])
        elif n < 65536:
            head += bytes([0x80 | 126]) + struct.pack("!H", n)
        else:
            head += bytes([0x80 | 127]) + struct.pack("!Q", n)
        mask = os.urandom(4)
        body = bytes(b ^ mask[i % 4] for i, b in enumerate(payload))
        self.sock.sendall(head + mask + body)

    def send(self, message):
        """A dict as one JSON text message (a str is sent as it is)."""
        text = message if isinstance(message, str) else json.dumps(message)
        self.send_frame(0x1, text.encode())

    def read_frame(self):
        """(opcode, payload) of the next whole message; answers pings; a close raises WebError."""
        data = b""
        while True:
            b0, b1 = self._take(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack("!H", self._take(2))[0]
            elif n == 127:
                n = struct.unpack("!Q", self._take(8))[0]
            payload = self._take(n)  # the server never masks
            op = b0 & 0x0F
            if op == 0x8:
                self.close_code = struct.unpack("!H", payload[:2])[0] if len(payload) >= 2 else None
                raise WebError(f"the server closed the WebSocket (code {self.close_code})")
            if op == 0x9:
                self.send_frame(0xA, payload)
                continue
            if op == 0xA:
                continue
            data += payload
            if b0 & 0x80:
                return op, data

    def receive(self, types=None, timeout=5.0):
        """The next message (a dict) whose type is `types` (a str or a tuple; None: any); others
        read on the way are kept for later calls. WebError after `timeout` seconds."""
        if isinstance(types, str):
            types = (types,)
        for i, m in enumerate(self.pending):
            if types is None or m["type"] in types:
                return self.pending.pop(i)
        end = time.monotonic() + timeout
        while True:
            left = end - time.monotonic()
            if left <= 0:
                raise WebError(f"no {types} message within {timeout} s")
            self.sock.settimeout(left)
            try:
                _, data = self.read_frame()
            except socket.timeout as e:
                raise WebError(f"no {types} message within {timeout} s") from e
            m = json.loads(data)
            if types is None or m["type"] in types:
                return m
            if m["type"] != "state":  # states go stale: never kept
                self.pending.append(m)

    def request(self, message, types=None, timeout=5.0):
        """Sends `message` and returns its answer: an "error", or a message of `types` (default:
        the status for "status", "scene" for "scene", "ack" for the rest)."""
        if types is None:
            t = message["type"]
            types = {"status": "status", "scene": "scene", "load": "loaded"}.get(t, "ack")
        self.send(message)
        return self.receive((types, "error") if isinstance(types, str) else (*types, "error"),
                            timeout)

    def close(self):
        try:
            self.send_frame(0x8, struct.pack("!H", 1000))
        except OSError:
            pass
        self.sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
