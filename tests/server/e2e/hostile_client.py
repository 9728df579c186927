#!/usr/bin/env python3
"""A concurrent hostile client for `devsurf serve` (issue 12): about ten connections at once, on
loopback only, bounded in messages and time, seeded so that a failing run can be repeated.

It starts the daemon itself (every examples/*.json as a demo session, or the first N of each kind with --demos-per-kind N, a fresh data directory, the
daemon's stderr captured) and mixes, per connection:
  - valid joins and edits on the demo sessions of every kind (drags ending in drag_end, handles,
    fixed points, creases, model parameters, solver settings, undo/redo/reset, solve),
  - 5 MB strings, deep nesting, random binary frames, invalid UTF-8 text frames, huge numbers,
    extreme coordinates, random messages, broken WebSocket framing,
  - malformed, mutated and oversized REST bodies, chunked bodies, garbage requests,
while another task asks GET /api/health every two seconds.

It fails (exit 1) when the daemon dies or does not exit 0 on SIGTERM, when its stderr holds a
sanitizer report (AddressSanitizer, LeakSanitizer, UndefinedBehaviorSanitizer, ThreadSanitizer),
when /api/health stops answering, when an edit or a request gets no answer in 120 s (a
drag_end's answer is its ack; its `solved` may come later, after other participants' work, and
is only counted), or when any reply is a 500 / `internal` error or carries a `null` or
non-finite number (JSON or float32 geometry arrays).

  hostile_client.py --bin build-fuzz/server/devsurf --seed 1 --messages 2000 --seconds 240
  hostile_client.py --bin build/server/devsurf --seed 7 --messages 30000 --seconds 3600   (long run)

Repeat a failure with the same --seed and --connections (the message streams are the same; their
interleaving is not). --keep keeps the data directory, the daemon's stderr and each connection's
log of what it sent.
"""
import argparse
import array
import asyncio
import base64
import glob
import hashlib
import json
import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
HOST = "127.0.0.1"  # loopback only
SANITIZER_REPORT = re.compile(r"ERROR: AddressSanitizer|ERROR: LeakSanitizer|runtime error:|"
                              r"WARNING: ThreadSanitizer|ERROR: ThreadSanitizer|SUMMARY: \w+Sanitizer")
# Keys whose value may be null by contract (docs/protocol.md, the schemas): a presence selection
# or drag of nothing, a cylinder's projection point, and per-edge values of a FOLD export that
# the format writes as null (io/FoldWriter.h: an edge without a curve).
# Keys whose null is documented (docs/protocol.md): nothing selected or dragged, no development
# managed (a composite without one, a conical strip not solved yet), no curvature asked for (a
# quad_mesh without gauss_image) — absence, not a non-finite metric or coordinate.
NULLABLE_KEYS = {"selection", "dragging", "projection_point", "edges_devsurf:curve", "edges_foldAngle",
                 "development", "curvature"}
MAX_BODY = 2 << 20  # the daemon runs with --max-body 2 MiB, so oversized bodies stay cheap


class Failures:
    """Findings, each kept once with the first place it was seen and how often."""

    def __init__(self):
        self.seen = {}

    def add(self, where, what):
        if what in self.seen:
            self.seen[what][1] += 1
        elif len(self.seen) < 200:
            self.seen[what] = [where, 1]

    @property
    def items(self):
        return [f"{where}: {what}" + (f" (× {n})" if n > 1 else "") for what, (where, n) in self.seen.items()]


def check_value(value, where, failures, key=None, depth=0):
    """Every null outside NULLABLE_KEYS and every non-finite number, including float32 arrays."""
    if depth > 200:
        return
    if value is None:
        if key not in NULLABLE_KEYS:
            failures.add(where, f"null at key {key!r}")
    elif isinstance(value, float):
        if not math.isfinite(value):
            failures.add(where, f"non-finite number at key {key!r}")
    elif isinstance(value, list):
        for v in value:
            check_value(v, where, failures, key, depth + 1)
    elif isinstance(value, dict):
        if value.get("dtype") == "float32" and isinstance(value.get("data"), str):
            floats = array.array("f")
            data = base64.b64decode(value["data"])
            floats.frombytes(data[:len(data) // 4 * 4])
            if not math.isfinite(sum(floats)):  # NaN and ±inf propagate; float32s cannot overflow a double sum
                failures.add(where, f"non-finite float32 in array {key!r}")
        for k, v in value.items():
            check_value(v, where, failures, k, depth + 1)


def parse_reply(text, where, failures):
    def constant(name):
        failures.add(where, f"non-finite JSON literal {name}")
        return 0.0
    try:
        message = json.loads(text, parse_constant=constant)
    except (ValueError, UnicodeDecodeError) as e:
        failures.add(where, f"reply is not JSON ({e}): {text[:200]!r}")
        return None
    check_value(message, where, failures)
    if isinstance(message, dict):
        error = message.get("error") if isinstance(message.get("error"), dict) else message
        if error.get("code") == "internal" or (message.get("type") == "error" and message.get("code") == "internal"):
            failures.add(where, f"internal error: {text[:300]}")
    return message


# --- HTTP on raw sockets ---------------------------------------------------------------------------

async def http(port, raw, timeout=90.0):
    """Sends raw request bytes; returns (status, headers, body) or None when the peer closed first."""
    reader, writer = await asyncio.wait_for(asyncio.open_connection(HOST, port), timeout)
    try:
        writer.write(raw)
        await writer.drain()
        head = await asyncio.wait_for(reader.readuntil(b"\r\n\r\n"), timeout)
        lines = head.decode("latin-1").split("\r\n")
        status = int(lines[0].split()[1])
        headers = {}
        for line in lines[1:]:
            if ":" in line:
                k, v = line.split(":", 1)
                headers[k.strip().lower()] = v.strip()
        if "content-length" in headers:
            body = await asyncio.wait_for(reader.readexactly(int(headers["content-length"])), timeout)
        elif headers.get("transfer-encoding", "").lower() == "chunked":
            body = b""
            while True:
                size = int((await asyncio.wait_for(reader.readuntil(b"\r\n"), timeout)).split(b";")[0], 16)
                chunk = await asyncio.wait_for(reader.readexactly(size + 2), timeout)
                if size == 0:
                    break
                body += chunk[:-2]
        else:
            body = await asyncio.wait_for(reader.read(), timeout)
        return status, headers, body
    except (asyncio.IncompleteReadError, ConnectionError, IndexError, ValueError):
        return None
    finally:
        writer.close()
        try:
            await writer.wait_closed()
        except (ConnectionError, OSError):
            pass


def request(method, path, body=None, headers=None, content_type="application/json"):
    h = {"Host": f"{HOST}", "Connection": "close"}
    if body is not None:
        h["Content-Type"] = content_type
        h["Content-Length"] = str(len(body))
    h.update(headers or {})
    head = f"{method} {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in h.items()) + "\r\n"
    return head.encode() + (body or b"")


# --- WebSocket on raw sockets ----------------------------------------------------------------------

class RawWebSocket:
    """A client that can send any frame, valid or not. A reader task checks every reply."""

    def __init__(self, port, rng, failures, where):
        self.port, self.rng, self.failures, self.where = port, rng, failures, where
        self.inbox = asyncio.Queue()
        self.closed = False
        self.close_info = None  # (code, reason) of the server's close frame
        self.replies = 0

    async def open(self):
        self.reader, self.writer = await asyncio.wait_for(asyncio.open_connection(HOST, self.port), 30)
        key = base64.b64encode(self.rng.randbytes(16)).decode()
        self.writer.write((f"GET /ws HTTP/1.1\r\nHost: {HOST}:{self.port}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
        head = await asyncio.wait_for(self.reader.readuntil(b"\r\n\r\n"), 60)
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise ConnectionError("no upgrade: " + head[:100].decode("latin-1"))
        self.task = asyncio.ensure_future(self.read_loop())
        return self

    def frame(self, opcode, payload, fin=True, rsv=0, masked=True, declared=None):
        n = len(payload) if declared is None else declared
        head = bytes([(0x80 if fin else 0) | (rsv << 4) | opcode])
        m = 0x80 if masked else 0
        if n < 126:
            head += bytes([m | n])
        elif n < 65536:
            head += bytes([m | 126]) + n.to_bytes(2, "big")
        else:
            head += bytes([m | 127]) + n.to_bytes(8, "big")
        if not masked:
            return head + payload
        mask = self.rng.randbytes(4)
        return head + mask + bytes(b ^ mask[i & 3] for i, b in enumerate(payload)) if len(payload) < 4096 \
            else head + mask + _xor(payload, mask)

    async def send_raw(self, data):
        if self.closed:
            return False
        try:
            self.writer.write(data)
            await asyncio.wait_for(self.writer.drain(), 60)
            return True
        except (ConnectionError, asyncio.TimeoutError, OSError):
            self.closed = True
            return False

    async def send_text(self, text):
        data = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
        return await self.send_raw(self.frame(0x1, data))

    async def read_loop(self):
        try:
            buffer = b""
            while True:
                b0, b1 = await self.reader.readexactly(2)
                n = b1 & 0x7F
                if n == 126:
                    n = int.from_bytes(await self.reader.readexactly(2), "big")
                elif n == 127:
                    n = int.from_bytes(await self.reader.readexactly(8), "big")
                if b1 & 0x80:
                    self.failures.add(self.where, "the server sent a masked frame")
                    await self.reader.readexactly(4)
                payload = await self.reader.readexactly(n)
                opcode = b0 & 0x0F
                if opcode == 0x8:
                    self.close_info = (int.from_bytes(payload[:2], "big") if len(payload) >= 2 else None,
                                       payload[2:].decode("utf-8", "replace"))
                    break
                if opcode == 0x9:  # answer the server's keep-alive ping, as a browser does
                    self.writer.write(self.frame(0xA, payload[:125]))
                    continue
                if opcode == 0xA:
                    continue
                buffer += payload
                if not b0 & 0x80:
                    continue
                data, buffer = buffer, b""
                self.replies += 1
                if opcode != 0x1 and opcode != 0x0:
                    self.failures.add(self.where, f"the server sent a frame with opcode {opcode}")
                    continue
                message = parse_reply(data.decode("utf-8", "replace"), self.where, self.failures)
                if isinstance(message, dict):
                    self.inbox.put_nowait(message)
        except (asyncio.IncompleteReadError, ConnectionError, OSError) as e:
            self.close_info = self.close_info or (None, f"{type(e).__name__}: {e}")
        except Exception as e:  # a reply this client cannot read is a finding, not a silent end
            self.failures.add(self.where, f"unreadable reply: {type(e).__name__}: {e}")
        finally:
            self.closed = True
            self.inbox.put_nowait(None)

    async def wait_for(self, predicate, timeout):
        """The first message that satisfies predicate, or None (closed, or timed out)."""
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            try:
                m = await asyncio.wait_for(self.inbox.get(), left)
            except asyncio.TimeoutError:
                return None
            if m is None:
                self.inbox.put_nowait(None)
                return None
            if predicate(m):
                return m

    async def close(self):
        self.closed = True
        try:
            self.writer.close()
            await self.writer.wait_closed()
        except (ConnectionError, OSError):
            pass
        if hasattr(self, "task"):
            self.task.cancel()
            try:
                await self.task
            except (asyncio.CancelledError, Exception):
                pass


def _xor(payload, mask):
    n = len(payload)
    m = (mask * (n // 4 + 1))[:n]
    return (int.from_bytes(payload, "little") ^ int.from_bytes(m, "little")).to_bytes(n, "little")


# --- what to send ----------------------------------------------------------------------------------

HUGE_NUMBERS = ["1e308", "-1e308", "1e400", "-1e400", "1e-400", "4.9e-324", "-0.0", "99999999999999999999999999",
                "-9223372036854775809", "18446744073709551616", "2147483648", "4294967299", "1e9", "-1e9",
                "1000000000.5", "123456789012345678901234567890e-10"]


def targets_of(scene):
    """Every addressable point of a scene: (target, position)."""
    model = scene["model"]
    out = []
    for c in ("a", "b", "c1", "c2", "p", "q"):
        if isinstance(model.get(c), dict):
            for i, p in enumerate(model[c].get("points", [])):
                out.append(({"curve": c, "index": i}, p[:3]))
    for i, p in enumerate(model.get("vertices", [])):
        out.append(({"vertex": i}, p[:3]))
    for e, edge in enumerate(model.get("edges", [])):
        for k, p in enumerate(edge.get("points", [])):
            out.append(({"edge": e, "index": k}, p[:3]))
    if model.get("kind") == "quad_mesh":  # vertices of M, and of M′ (z = 0 when planar)
        # (issue 13's spelling: "mesh": {"vertices", "faces"}, "unfolding": {"vertices", "planar"})
        for i, p in enumerate(model.get("mesh", {}).get("vertices", [])):
            out.append(({"vertex": i}, p[:3]))
        for i, p in enumerate(model.get("unfolding", {}).get("vertices", [])):
            out.append(({"vertex": i, "on": "unfolding"}, (list(p) + [0.0])[:3]))
        # A spline surface: its control points (the scene file may give no mesh: the loader
        # writes S^k(M) from the net).
        control = model.get("control")
        if isinstance(control, dict):
            for i, p in enumerate(control.get("points", [])):
                out.append(({"vertex": i, "on": "control"}, p[:3]))
    return out


def size_of(scene):
    pts = [p for _, p in targets_of(scene)] or [[0, 0, 0]]
    return max(1e-3, max(max(p[i] for p in pts) - min(p[i] for p in pts) for i in range(3)))


def mutate(rng, value, depth=0):
    """One random mutation somewhere in a JSON value (a copy)."""
    if isinstance(value, dict) and value and depth < 8:
        k = rng.choice(sorted(value))
        out = dict(value)
        r = rng.random()
        if r < 0.06:
            del out[k]
        elif r < 0.1:
            out["x" * rng.randint(1, 3)] = rng.choice([1, "s", None, [], {}])
        else:
            out[k] = mutate(rng, value[k], depth + 1)
        return out
    if isinstance(value, list) and value and depth < 8:
        out = list(value)
        i = rng.randrange(len(out))
        r = rng.random()
        if r < 0.05:
            del out[i]
        elif r < 0.1:
            out.append(out[i])
        elif r < 0.12:
            out = out * rng.randint(2, 40)
        else:
            out[i] = mutate(rng, value[i], depth + 1)
        return out
    return rng.choice([-1, 0, 1, 2, 7, 2 ** 31, 2 ** 32 + 3, 2 ** 63 - 1, -2 ** 63, 1e200, -1e300, 1e9 + 1, 1e-300,
                       0.5, "s", "", "x" * rng.randint(1, 5000), None, True, [], {}, [0, 0, 0], [[1, 2, 3]],
                       value * 10 if isinstance(value, (int, float)) and not isinstance(value, bool) else 3])


def random_json(rng, depth=0):
    r = rng.random()
    if depth > 4 or r < 0.4:
        return rng.choice([0, -1, 1.5, 2 ** 40, 1e300, "", "a", "b", "c1", "p", "vertex", "drag", None, True, False])
    if r < 0.7:
        return [random_json(rng, depth + 1) for _ in range(rng.randint(0, 4))]
    keys = ["type", "op", "target", "position", "curve", "index", "vertex", "edge", "fixed", "weight", "solver",
            "params", "iterations", "selection", "name", "session", "token", "crease", "normals"]
    return {rng.choice(keys): random_json(rng, depth + 1) for _ in range(rng.randint(0, 5))}


class Worker:
    def __init__(self, index, args, examples, failures, budget, deadline):
        self.i = index
        self.rng = random.Random(hashlib.sha256(f"{args.seed}:{index}".encode()).digest())
        self.args, self.examples, self.failures, self.budget, self.deadline = args, examples, failures, budget, deadline
        self.port = args.port
        self.log = open(os.path.join(args.out, f"worker-{index}.log"), "w")
        self.sent = 0
        self.created = []  # (id, edit token, scene) of sessions this worker created
        self.counts = {}
        self.unanswered = 0
        self.solved_late = 0     # drag_ends acked whose `solved` did not come within 120 s
        self.solved_after = []   # seconds from a drag_end to its `solved`

    def note(self, kind, detail=""):
        self.sent += 1
        self.budget[0] -= 1
        self.counts[kind] = self.counts.get(kind, 0) + 1
        self.log.write(f"{self.sent} {kind} {detail[:300]}\n")

    def no_answer(self, ws, kind, since):
        self.unanswered += 1
        self.log.write(f"  no answer to {kind} after {time.monotonic() - since:.1f} s "
                       f"({f'closed {ws.close_info}' if ws.closed else 'open'})\n")

    def more(self):
        return self.budget[0] > 0 and time.monotonic() < self.deadline

    async def run(self):
        actions = [(self.valid_session, 40), (self.hostile_ws, 25), (self.framing, 8), (self.rest_bodies, 15),
                   (self.rest_reads, 8), (self.garbage_http, 4), (self.rest_meshes, 3)]
        total = sum(w for _, w in actions)
        while self.more():
            r = self.rng.uniform(0, total)
            for action, w in actions:
                r -= w
                if r <= 0:
                    break
            try:
                await action()
            except (ConnectionError, asyncio.TimeoutError, asyncio.IncompleteReadError, OSError) as e:
                self.log.write(f"  connection: {type(e).__name__} {e}\n")
        self.log.close()

    # REST ----------------------------------------------------------------------------------------
    async def rest(self, raw, kind, detail, expect_answer=True):
        self.note(kind, detail)
        where = f"worker {self.i} message {self.sent} ({kind})"
        reply = await http(self.port, raw)
        if reply is None:
            if expect_answer:
                self.unanswered += 1
                self.log.write("  no answer\n")
            return None
        status, headers, body = reply
        self.log.write(f"  {status} {body[:160]!r}\n")
        if status >= 500 and status != 503:
            self.failures.add(where, f"HTTP {status}: {body[:300]!r} after {detail[:200]}")
        if "json" in headers.get("content-type", "") and body:
            return status, parse_reply(body.decode("utf-8", "replace"), where, self.failures)
        return status, None

    async def rest_bodies(self):
        rng = self.rng
        route = rng.choice(["/api/sessions", "/api/sessions", "/api/jobs"])
        scene = json.loads(json.dumps(rng.choice(self.examples)[1]))
        r = rng.random()
        if r < 0.45:
            for _ in range(rng.randint(1, 4)):
                scene = mutate(rng, scene)
            body = json.dumps(scene).encode()
        elif r < 0.55:
            body = rng.choice([b"[]", b"5", b"null", b'"x"', b"{}", b"", b"{", b"{\"model\":", b"NaN", b"[1e999]",
                               b'{"format":"devsurf-scene","version":1,"model":{"kind":"strip"}}',
                               b'{"solver":5}', b'{"solver":{"iterations":"10"}}', b"\xff\xfe\xfd"])
        elif r < 0.62:
            body = json.dumps(scene).encode()
            i = rng.randrange(len(body))
            body = body[:i] + bytes([rng.choice([0x80, 0xC3, 0xFF, 0xED, 0xF4])]) + body[i + 1:]
        elif r < 0.7:
            depth = rng.choice([65, 1000, 100000])
            body = (b'{"format":"devsurf-scene","version":1,"model":' + b"[" * depth + b"]" * depth + b"}")
        elif r < 0.76:
            body = b'{"name":"' + b"n" * (MAX_BODY + rng.randint(1, 1 << 20)) + b'"}'
        elif r < 0.82:
            body = json.dumps(scene).encode()
            chunks = []
            for i in range(0, len(body), 4096):
                piece = body[i:i + 4096]
                chunks.append(f"{len(piece):x}\r\n".encode() + piece + b"\r\n")
            raw = request("POST", route, headers={"Content-Type": "application/json", "Transfer-Encoding": "chunked"})
            return await self.rest(raw + b"".join(chunks) + b"0\r\n\r\n", "rest.chunked", route)
        else:
            body = json.dumps(scene).encode()  # valid: creates a session or a job
        reply = await self.rest(request("POST", route, body), "rest.post", f"{route} {body[:200]!r}")
        if reply and reply[0] == 201 and isinstance(reply[1], dict) and "edit_token" in reply[1]:
            self.created.append((reply[1]["id"], reply[1]["edit_token"], scene))
        if reply and reply[0] in (200, 202) and isinstance(reply[1], dict) and "id" in reply[1]:
            self.created_job = reply[1]["id"]

    async def rest_meshes(self):
        """POST /api/approximations, /api/references, /api/fits, /api/covers: small meshes and clouds, broken ones and
        hostile parameters (issue 15)."""
        rng = self.rng
        n = rng.randint(1, 6)
        verts = [f"{i / n} {j / n} {0.2 * rng.random()}" for j in range(n + 1) for i in range(n + 1)]
        faces = []
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i
                faces += [f"3 {a} {a + 1} {a + n + 2}", f"3 {a} {a + n + 2} {a + n + 1}"]
        header = f"{len(verts)} {len(faces)} 0"
        r = rng.random()
        if r < 0.15:
            header = rng.choice(["999999999 1 0", "-1 -1 0", "3 4000000000 0", "nan 1 0"])
        elif r < 0.3:
            verts[rng.randrange(len(verts))] = rng.choice(["nan 0 0", "inf 1 2", "1e400 0 0", "x y z", ""])
        elif r < 0.4:
            faces[rng.randrange(len(faces))] = rng.choice(["3 0 0 0", "3 0 1 99999", "4 0 1 2", "3 -1 0 1", "2 0 1"])
        body = ("OFF\n" + header + "\n" + "\n".join(verts + faces) + "\n").encode()
        if rng.random() < 0.1:
            body = body[:rng.randrange(len(body))]
        if rng.random() < 0.05:
            body = bytes(rng.randrange(256) for _ in range(rng.randint(0, 2000)))
        params = {"format": rng.choice(["off", "off", "off", "obj", "ply", "stl", "", "dxf"])}
        for key, values in [("segments", ["1", "3", "0", "-2", "1e9", "x"]), ("faces", ["50", "4", "100001", "nan"]),
                            ("spacing", ["0.2", "0", "-1", "1e308"]), ("iterations", ["5", "-1", "99999"]),
                            ("isometry", ["10", "-1", "inf"]), ("units", ["cm", "parsec"]), ("bogus", ["1"])]:
            if rng.random() < 0.2:
                params[key] = rng.choice(values)
        route = "/api/approximations"
        if rng.random() < 0.4:
            # The same shapes (and clouds of their vertices) to preview, fit a strip to, or cover.
            route = rng.choice(["/api/references", "/api/fits", "/api/covers"])
            if rng.random() < 0.4:
                body = ("\n".join(verts) + "\n").encode()
                params["format"] = rng.choice(["xyz", "pwn", "xyz", "off"])
            params = {"format": params["format"]}
            for key, values in [("centre", ["0.5,0.5,0", "0,0", "nan,0,0", "1e308,0,0"]), ("radius", ["0.4", "0", "-1", "inf"]),
                                ("thin", ["0.05", "0", "1e-300"]), ("strips", ["2", "0", "65", "x"]), ("rounds", ["1", "101"]),
                                ("control_points", ["4", "3", "201"]), ("crease", ["fold", "valley"]),
                                ("points", ["10", "0", "200001"]), ("flat", ["true", "maybe"]),
                                ("regions", ["2", "3", "0", "33", "x"]), ("overhang", ["0.001", "-1", "nan"]), ("bogus", ["1"])]:
                if rng.random() < 0.2:
                    params[key] = rng.choice(values)
        query = "&".join(f"{k}={v}" for k, v in params.items())
        raw = request("POST", route + "?" + query, body, content_type="application/octet-stream")
        await self.rest(raw, "rest.mesh", f"{route}?{query} {body[:120]!r}")

    async def rest_reads(self):
        rng = self.rng
        sid, token = ("nosuch", "x")
        if self.created and rng.random() < 0.7:
            sid, token, _ = rng.choice(self.created)
        elif self.args.demos:
            d = rng.choice(self.args.demos)
            sid, token = d["id"], rng.choice([d["edit_token"], d["view_token"]])
        token = rng.choice([token, token, "", "x" * 5000, token[:-1] + "A"])
        auth = {"Authorization": "Bearer " + token}
        job = getattr(self, "created_job", "nosuchjob")
        path, method = rng.choice([
            (f"/api/sessions/{sid}", "GET"), (f"/api/sessions/{sid}/export?format=" +
                                             rng.choice(["json", "obj", "stl", "iges", "svg", "fold", "", "%00", "x" * 300]), "GET"),
            (f"/api/jobs/{job}", "GET"), (f"/api/jobs/{job}/result", "GET"),
            (f"/api/jobs/{job}/result?format=" + rng.choice(["obj", "stl", "iges", "svg", "nope"]), "GET"),
            (f"/api/jobs/{job}/cancel", "POST"), ("/api/metrics", "GET"), ("/api/sessions", "GET"),
            ("/api/openapi.json", "GET"), (f"/api/sessions/{sid}", "DELETE")])
        if method == "DELETE" and (sid, token) not in [(c[0], c[1]) for c in self.created]:
            method = "GET"
        await self.rest(request(method, path, headers=auth), "rest.read", f"{method} {path}")
        if method == "DELETE":
            self.created = [c for c in self.created if c[0] != sid]

    async def garbage_http(self):
        rng = self.rng
        choice = rng.randrange(6)
        if choice == 0:
            raw = rng.randbytes(rng.randint(1, 2000)) + b"\r\n\r\n"
        elif choice == 1:
            raw = b"GET /api/health HTTP/1.1\r\n" + b"".join(b"X-H%d: v\r\n" % i for i in range(rng.randint(100, 3000))) + b"\r\n"
        elif choice == 2:
            raw = b"POST /api/sessions HTTP/1.1\r\nContent-Length: 99999999999\r\nContent-Type: application/json\r\n\r\n{}"
        elif choice == 3:
            raw = b"GET /api/" + b"a%" * rng.randint(10, 5000) + b" HTTP/1.1\r\n\r\n"
        elif choice == 4:
            raw = request(rng.choice(["PATCH", "PUT", "OPTIONS", "HEAD", "TRACE", "BREW"]), rng.choice(["/api/sessions", "/ws", "/", "/api/jobs/x"]))
        else:
            raw = (b"POST /api/jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\nContent-Type: application/json\r\n\r\n" +
                   rng.choice([b"zz\r\n{}\r\n0\r\n\r\n", b"ffffffffffffffff\r\n{}\r\n", b"5\r\n{}\r\n0\r\n\r\n", b"2\r\n{}"]))
        await self.rest(raw, "http.garbage", repr(raw[:120]), expect_answer=False)

    # WebSocket -----------------------------------------------------------------------------------
    async def connect(self):
        return await RawWebSocket(self.port, self.rng, self.failures, f"worker {self.i} ws").open()

    async def join(self, ws, session, token, name="hostile"):
        await ws.send_text(json.dumps({"type": "join", "session": session, "token": token, "name": name}))
        self.note("ws.join", session)
        return await ws.wait_for(lambda m: m.get("type") in ("state", "error"), 120)

    async def valid_session(self):
        rng = self.rng
        if self.created and rng.random() < 0.25:
            sid, token, _ = rng.choice(self.created)
        else:
            d = rng.choice(self.args.demos)
            sid, token = d["id"], d["edit_token"]
        ws = await self.connect()
        try:
            state = await self.join(ws, sid, token)
            if not state or state.get("type") != "state":
                return
            scene = state["scene"]
            kind = scene["model"]["kind"]
            points = targets_of(scene)
            size = size_of(scene)
            op = 0
            for _ in range(rng.randint(1, 6)):
                if not self.more() or ws.closed:
                    break
                op += 1
                r = rng.random()
                target, p = rng.choice(points)
                if r < 0.45:  # a drag: moves, then drag_end, then wait for solved
                    far = rng.random() < 0.1
                    for _ in range(rng.randint(1, 8)):
                        scale = rng.choice([size * 80, 1e6, 1e9]) if far else size * 0.15
                        position = [p[k] + rng.uniform(-scale, scale) for k in range(3)]
                        await ws.send_text(json.dumps({"type": "drag", "op": op, "target": target, "position": position}))
                        self.note("ws.drag", json.dumps(position))
                    end = f"{op}-end"  # its own op: the drags' acks carry `op`
                    await ws.send_text(json.dumps({"type": "drag_end", "op": end, "target": target,
                                                   **({"iterations": rng.randint(0, 50)} if rng.random() < 0.3 else {})}))
                    self.note("ws.drag_end")
                    t0 = time.monotonic()
                    # The answer is the ack (every edit gets one) or an error. `solved` follows the
                    # release, which other participants' newer work interrupts and postpones (the
                    # settle comes when the session is idle): under ten hostile connections on
                    # shared demo sessions it may come much later, which is counted, not failed.
                    applied = []  # acks of the drags: a let-go of drags all refused gets an ack and no release

                    def let_go_answered(m, end=end, op=op, applied=applied):
                        if m.get("op") == op and m.get("type") == "ack":
                            applied.append(m)
                        return m.get("op") == end and m.get("type") in ("ack", "error")

                    answer = await ws.wait_for(let_go_answered, 120)
                    if answer is None:
                        self.no_answer(ws, "drag_end", t0)
                    elif answer["type"] == "ack" and applied:
                        if await ws.wait_for(lambda m, end=end: m.get("type") == "solved" or (m.get("type") == "error" and m.get("op") == end), 120):
                            self.solved_after.append(time.monotonic() - t0)
                        else:
                            self.solved_late += 1
                            self.log.write(f"  drag_end acked, no solved in 120 s ({'closed' if ws.closed else 'open'})\n")
                    continue
                if r < 0.55:
                    m = {"type": "set_fixed", "target": target, "fixed": rng.random() < 0.5}
                elif r < 0.65:
                    m = ({"type": "add_handle", "target": target, "weight": rng.choice([0.1, 1, 100, 1e6]),
                          "position": [p[k] + rng.uniform(-size, size) * 0.3 for k in range(3)]}
                         if rng.random() < 0.6 else {"type": "remove_handle", "target": target})
                elif r < 0.72:
                    m = {"type": "set_crease", "edge": rng.randrange(len(scene["model"].get("edges", [1]))),
                         "crease": rng.choice(["none", "fold", "geodesic", "smooth"])}
                elif r < 0.8:
                    params = ({"samples": rng.randint(10, 200), "mapping": {"degree": rng.randint(1, 4), "coefficients": rng.randint(5, 60)},
                               "method": rng.choice(["bspline", "discrete"]), "lambda1": rng.uniform(0, 1)}
                              if kind == "quasi_strip" else
                              {"np": rng.randint(5, 80), "nq": rng.randint(5, 80), "h3": rng.uniform(0.3, 4), "h4": rng.uniform(0.1, 4),
                               "ra": rng.uniform(1, 2), "objective": rng.choice(["normal_variation", "bending_energy"]), "g1": rng.random() < 0.5})
                    keys = rng.sample(sorted(params), rng.randint(1, len(params)))
                    m = {"type": "set_params", "params": {k: params[k] for k in keys}}
                elif r < 0.86:
                    solver = {"fairness": rng.choice([0, 0.01, 1]), "iterations": rng.randint(1, 40),
                              "regularization": rng.choice([0, 1e-3, 0.01, 10]), "step_control": rng.random() < 0.8,
                              "handle_weight": rng.choice([0.01, 1, 1e6]), "time_budget_ms": rng.choice([0, 10, 500])}
                    keys = rng.sample(sorted(solver), rng.randint(1, 3))
                    m = {"type": "set_solver", "solver": {k: solver[k] for k in keys}}
                    if rng.random() < 0.3:
                        m["drag_iterations"] = rng.randint(1, 100)
                elif r < 0.9 and kind == "composite":  # the labelled mesh edited: any indices
                    edges, faces = len(scene["model"].get("edges", [])), len(scene["model"].get("faces", []))
                    m = rng.choice([
                        {"type": "relabel_edge", "edges": [rng.randrange(edges + 2) for _ in range(rng.randint(1, 4))],
                         "label": rng.choice(["R", "S"])},
                        {"type": "split_face", "face": rng.randrange(faces + 1),
                         "vertices": [rng.randrange(len(scene["model"].get("vertices", [])) + 1) for _ in range(2)]},
                        {"type": "merge_faces", "edge": rng.randrange(edges + 1)},
                        {"type": "split_along_ruling", "edge": rng.randrange(edges + 1),
                         "at": rng.choice([rng.random(), 0.0, 1.0, 1e-12, 0.999999999])},
                        {"type": "split_edge", "edge": rng.randrange(edges + 1), "at": rng.choice([rng.random(), 1e-12, 2.0])},
                        {"type": "remove_vertex", "vertex": rng.randrange(len(scene["model"].get("vertices", [])) + 1)},
                    ])
                elif r < 0.95:
                    m = {"type": rng.choice(["undo", "redo", "reset", "undo"])}
                else:
                    m = {"type": "solve", "iterations": rng.randint(1, 60)}
                m["op"] = op
                await ws.send_text(json.dumps(m))
                self.note("ws." + m["type"], json.dumps(m))
                t0 = time.monotonic()
                if not await ws.wait_for(lambda x, op=op: x.get("op") == op and x.get("type") in ("ack", "error")
                                         or (m["type"] == "solve" and x.get("type") == "solved"), 120):
                    self.no_answer(ws, m["type"], t0)
            if rng.random() < 0.3:  # leave mid-drag
                target, p = rng.choice(points)
                await ws.send_text(json.dumps({"type": "drag", "op": op + 1, "target": target, "position": [v + 0.05 for v in p]}))
                self.note("ws.drag_then_leave")
        finally:
            await ws.close()

    async def hostile_ws(self):
        rng = self.rng
        ws = await self.connect()
        try:
            if self.args.demos and rng.random() < 0.6:
                d = rng.choice(self.args.demos)
                await self.join(ws, d["id"], rng.choice([d["edit_token"], d["view_token"]]))
                points = targets_of(next(s for name, s in self.examples if "demo-" + name == d["id"]))
            else:
                points = [({"curve": "a", "index": 1}, [0, 0, 0])]
            for _ in range(rng.randint(1, 10)):
                if not self.more() or ws.closed:
                    break
                c = rng.randrange(11)
                target, p = rng.choice(points)
                if c == 0:  # a 5 MB string (beyond 4 × --max-message: the connection is closed)
                    data = json.dumps({"type": "presence", "name": "x" * (5 << 20)})
                    kind = "ws.5mb"
                elif c == 1:  # a string below the message limit
                    data = json.dumps({"type": rng.choice(["ping", "drag", "join"]), "op": "o" * rng.randint(65, 900000)})
                    kind = "ws.long_string"
                elif c == 2:
                    depth = rng.choice([63, 64, 65, 1000, 80000, 300000])
                    open_, close_ = rng.choice([("[", "]"), ('{"a":', "}")])
                    data = '{"type":"ping","op":' + open_ * depth + "1" + close_ * depth + "}"
                    kind = "ws.deep"
                elif c == 3:
                    await ws.send_raw(ws.frame(0x2, rng.randbytes(rng.randint(0, 70000))))
                    self.note("ws.binary")
                    continue
                elif c == 4:
                    raw = json.dumps({"type": "ping", "op": "abc"}).encode()
                    i = rng.randrange(len(raw))
                    raw = raw[:i] + rng.choice([b"\xff", b"\xc3", b"\xed\xa0\x80", b"\xf4\x90\x80\x80", b"\x80\x80"]) + raw[i:]
                    await ws.send_text(raw)
                    self.note("ws.invalid_utf8", repr(raw))
                    continue
                elif c == 5:
                    num = lambda: rng.choice(HUGE_NUMBERS)
                    data = rng.choice([
                        '{"type":"drag","op":1,"target":%s,"position":[%s,%s,%s]}' % (json.dumps(target), num(), num(), num()),
                        '{"type":"add_handle","op":1,"target":%s,"position":[%s,0,0],"weight":%s}' % (json.dumps(target), num(), num()),
                        '{"type":"drag","op":%s,"target":{"curve":"a","index":%s},"position":[0,0,0]}' % (num(), num()),
                        '{"type":"solve","iterations":%s}' % num(),
                        '{"type":"set_solver","solver":{"fairness":%s,"regularization":%s}}' % (num(), num())])
                    kind = "ws.huge_number"
                elif c == 6:
                    s = rng.choice([1e3, 1e6, 1e9, 1e12, 1e300])
                    data = json.dumps({"type": rng.choice(["drag", "add_handle"]), "op": 9, "target": target,
                                       "position": [rng.uniform(-s, s) for _ in range(3)]})
                    kind = "ws.extreme_coordinates"
                elif c == 7:
                    data = json.dumps(random_json(rng))
                    kind = "ws.random_json"
                elif c == 8:
                    data = json.dumps({"type": rng.choice(["drag", "drag_end", "add_handle", "set_fixed", "presence", "remove_handle"]),
                                       "target": rng.choice([{"curve": "q", "index": 99999}, {"vertex": 99999}, {"edge": 99999, "index": 0},
                                                             {"edge": 0, "index": 99999}, {"curve": "b", "index": -1}]),
                                       "position": [0, 0, 0], "fixed": True, "selection": None})
                    kind = "ws.bad_target"
                elif c == 9:
                    data = json.dumps({"type": "join", "session": rng.choice(["demo-strip-twisted", "x" * 64, ""]), "token": "t" * rng.randint(1, 129)})
                    kind = "ws.bad_join"
                else:
                    data = json.dumps(mutate(rng, {"type": "set_params", "op": 3, "params": {"np": 10, "samples": 40,
                                                   "mapping": {"degree": 2, "coefficients": 12}, "h3": 1.0}}))
                    kind = "ws.mutated_params"
                await ws.send_text(data)
                self.note(kind, data[:300])
            await ws.wait_for(lambda m: False, rng.uniform(0.05, 0.5))
        finally:
            await ws.close()

    async def framing(self):
        """Broken WebSocket framing: the server must drop or close, never crash."""
        rng = self.rng
        ws = await self.connect()
        try:
            c = rng.randrange(9)
            ping = json.dumps({"type": "ping", "op": 1}).encode()
            if c == 0:
                data = ws.frame(0x1, ping, rsv=rng.randint(1, 7))
            elif c == 1:
                data = ws.frame(rng.choice([3, 4, 5, 6, 7, 0xB, 0xC, 0xF]), ping)
            elif c == 2:
                data = ws.frame(0x0, ping)  # a continuation without a start
            elif c == 3:
                data = ws.frame(0x1, ping[:5], fin=False) + ws.frame(0x9, b"p") + ws.frame(0x0, ping[5:])
            elif c == 4:
                data = ws.frame(0x9, b"x" * 200)  # a control frame over 125 bytes
            elif c == 5:
                data = ws.frame(0x1, ping, masked=False)
            elif c == 6:
                data = ws.frame(0x1, ping, declared=rng.choice([1 << 62, (1 << 63) - 1, 1 << 40, 5 << 20]))
            elif c == 7:
                data = ws.frame(0x8, rng.choice([b"\x00", b"\x03\xe7", b"\x0b\xb8" + b"\xff\xfe", b"\x03\xe8" + b"r" * 200]))
            else:
                data = b"".join(ws.frame(0x1 if i == 0 else 0x0, ping[i:i + 1], fin=(i == len(ping) - 1)) for i in range(len(ping)))
            await ws.send_raw(data)
            self.note("ws.framing", f"case {c}")
            await ws.wait_for(lambda m: False, 0.3)
        finally:
            await ws.close()


# --- the run ---------------------------------------------------------------------------------------

async def health_monitor(port, failures, stop, proc, timeout):
    asked = 0
    while not stop.is_set():
        if proc.poll() is not None:
            failures.add("daemon", f"exited with {proc.returncode} during the run")
            return asked
        try:
            reply = await http(port, request("GET", "/api/health"), timeout=timeout)
            asked += 1
            if not reply or reply[0] != 200:
                failures.add("health", f"GET /api/health answered {reply and reply[0]}")
        except (asyncio.TimeoutError, ConnectionError, OSError) as e:
            failures.add("health", f"GET /api/health did not answer within {timeout} s: {type(e).__name__}")
        try:
            await asyncio.wait_for(stop.wait(), 2.0)
        except asyncio.TimeoutError:
            pass
    return asked


async def main_async(args, proc, examples, failures):
    budget = [args.messages]
    deadline = time.monotonic() + args.seconds
    workers = [Worker(i, args, examples, failures, budget, deadline) for i in range(args.connections)]
    stop = asyncio.Event()
    monitor = asyncio.ensure_future(health_monitor(args.port, failures, stop, proc, args.health_timeout))
    results = await asyncio.gather(*(w.run() for w in workers), return_exceptions=True)
    for w, r in zip(workers, results):
        if isinstance(r, BaseException):
            failures.add(f"worker {w.i}", f"client error {type(r).__name__}: {r}")
    stop.set()
    asked = await monitor
    return workers, asked


def select_examples(paths, per_kind):
    """The first `per_kind` examples of each kind (a spline control net counts as its own kind), or all."""
    if per_kind <= 0:
        return paths
    chosen, taken = [], {}
    for path in paths:
        model = json.load(open(path))["model"]
        kind = model["kind"] + ("/control" if "control" in model else "") + ("/approximation" if "approximation" in model else "")
        if taken.get(kind, 0) < per_kind:
            taken[kind] = taken.get(kind, 0) + 1
            chosen.append(path)
    return chosen


def start_daemon(args, data_dir, stderr_path):
    env = dict(os.environ)
    env.setdefault("ASAN_OPTIONS", "abort_on_error=1:halt_on_error=1:detect_leaks=1:allocator_may_return_null=1")
    # The transport's known shutdown cycle (see the file); everything else still counts.
    env.setdefault("LSAN_OPTIONS", "suppressions=" + os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                                  "lsan_transport_shutdown.supp") + ":print_suppressions=0")
    env.setdefault("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1")
    env.setdefault("TSAN_OPTIONS", "halt_on_error=0:second_deadlock_stack=1")
    demos = []
    for path in args.example_paths:
        demos += ["--demo", path]
    cmd = [args.bin, "serve", "--port", "0", "--bind", HOST, "--data", data_dir, "--max-body", str(MAX_BODY),
           "--message-rate", "1000", *demos, *args.daemon_arg]
    stderr = open(stderr_path, "w")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=stderr, text=True, env=env)
    line = proc.stdout.readline()
    m = re.search(r":(\d+)/", line)
    if not m:
        proc.wait(timeout=30)
        raise RuntimeError(f"the daemon did not start ({proc.returncode}): {line}\n" + open(stderr_path).read()[-3000:])
    return proc, int(m.group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bin", default=os.environ.get("DEVSURF_BIN", os.path.join(ROOT, "build", "server", "devsurf")))
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--connections", type=int, default=10)
    parser.add_argument("--messages", type=int, default=2000, help="stop after this many messages in all")
    parser.add_argument("--seconds", type=float, default=300, help="stop sending after this long")
    parser.add_argument("--health-timeout", type=float, default=60)
    parser.add_argument("--demos-per-kind", type=int, default=0,
                        help="open only the first N examples of each kind as demo sessions (0: all); the ASan "
                             "daemon takes ~2 s per demo to start")
    parser.add_argument("--keep", action="store_true", help="keep the data directory and the logs")
    parser.add_argument("--daemon-arg", action="append", default=[],
                        help="one more argument of `devsurf serve` (repeat: --daemon-arg=--release-iterations --daemon-arg=20)")
    args = parser.parse_args()
    args.out = tempfile.mkdtemp(prefix="devsurf-hostile-")
    data_dir = os.path.join(args.out, "data")
    stderr_path = os.path.join(args.out, "daemon.stderr")
    args.example_paths = select_examples(sorted(glob.glob(os.path.join(ROOT, "examples", "*.json"))), args.demos_per_kind)
    examples = [(os.path.splitext(os.path.basename(p))[0], json.load(open(p))) for p in args.example_paths]
    failures = Failures()
    started = time.monotonic()
    proc, args.port = start_daemon(args, data_dir, stderr_path)
    print(f"hostile_client: seed {args.seed}, {args.connections} connections, at most {args.messages} messages "
          f"in {args.seconds:.0f} s against {args.bin} (port {args.port}, started in {time.monotonic() - started:.1f} s)", flush=True)
    status_json = asyncio.run(http(args.port, request("GET", "/api/sessions")))
    args.demos = json.loads(status_json[2])["sessions"]
    kinds = sorted({s["model"]["kind"] for _, s in examples})
    if len(args.demos) != len(examples):
        failures.add("daemon", f"{len(args.demos)} demo sessions opened of {len(examples)} examples")
    workers, asked = asyncio.run(main_async(args, proc, examples, failures))
    elapsed = time.monotonic() - started
    code = proc.poll()
    if code is None:
        proc.send_signal(signal.SIGTERM)
        try:
            code = proc.wait(timeout=120)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait()
            failures.add("daemon", "did not exit within 120 s of SIGTERM")
    if code != 0:
        failures.add("daemon", f"exit code {code} (0 expected after SIGTERM)")
    stderr = open(stderr_path, errors="replace").read()
    reports = SANITIZER_REPORT.findall(stderr)
    if reports:
        failures.add("sanitizer", f"{len(reports)} report line(s) in the daemon's stderr:\n" + _excerpt(stderr))
    unanswered = sum(w.unanswered for w in workers)
    if unanswered:  # silence is not an answer (issue 12): every edit gets its ack or an error
        failures.add("silence", f"{unanswered} request(s) without an answer in 120 s (see 'no answer' in the worker logs)")
    sent = sum(w.sent for w in workers)
    counts = {}
    for w in workers:
        for k, v in w.counts.items():
            counts[k] = counts.get(k, 0) + v
    print(f"hostile_client: {sent} messages in {elapsed:.0f} s over {len(args.demos)} demo sessions ({', '.join(kinds)}); "
          f"{asked} health checks; {sum(w.unanswered for w in workers)} edits without an answer in 120 s")
    waits = sorted(t for w in workers for t in w.solved_after)
    if waits:
        print(f"  drag_end → solved: {len(waits)} in a median {waits[len(waits) // 2]:.2f} s, the slowest {waits[-1]:.1f} s; "
              f"{sum(w.solved_late for w in workers)} acked without `solved` in 120 s")
    print("  " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    if failures.items:
        print(f"hostile_client: FAILED, {len(failures.items)} finding(s) (seed {args.seed}; logs in {args.out}):")
        for f in failures.items[:40]:
            print("  - " + f)
        sys.exit(1)
    if args.keep:
        print(f"hostile_client: logs in {args.out}")
    else:
        shutil.rmtree(args.out, ignore_errors=True)
    print("hostile_client: passed (no crash, no sanitizer report, health answered, no 500/internal/null/non-finite reply)")


def _excerpt(stderr):
    i = max(0, SANITIZER_REPORT.search(stderr).start() - 200)
    return stderr[i:i + 4000]


if __name__ == "__main__":
    main()
