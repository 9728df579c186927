"""Issue 12: hostile input and access control, sent by an independent client."""
import asyncio
import subprocess
import hashlib
import json
import os
import random
import re
import shutil
import signal
import tempfile
import time
import unittest

import websockets

from daemon import (BIN, COMPOSITE, CONICAL, DEMO, QUASI, ROOT, Daemon, DaemonTestCase, drag, join,
                    numbers, recv_until)


class HostileInputTest(DaemonTestCase):
    """Issue 12: what an outside fuzzer sent that killed the daemon, sent again by this client."""
    PREFIX = "devsurf-hostile-"
    DAEMON_ARGS = ("--max-message", "262144")

    def alive(self):
        status, _, body = self.daemon.json("GET", "/api/health")
        self.assertEqual((status, body["status"]), (200, "ok"))

    def test_a_deeply_nested_frame_is_refused_unechoed_without_a_join(self):
        async def run():
            ws = await websockets.connect(f"ws://127.0.0.1:{self.daemon.port}/ws", max_size=None)
            answers = []
            for depth in (80000, 20000, 65):
                await ws.send('{"type":"ping","op":' + "[" * depth + "]" * depth + "}")
                answers.append(json.loads(await asyncio.wait_for(ws.recv(), 10)))
            await ws.send(json.dumps({"type": "ping", "op": [[1, 2], {"a": "b" * 1000}]}))
            answers.append(json.loads(await asyncio.wait_for(ws.recv(), 10)))
            await ws.send(json.dumps({"type": "ping", "op": 7}))
            answers.append(json.loads(await asyncio.wait_for(ws.recv(), 10)))
            await ws.close()
            return answers

        answers = asyncio.run(run())
        for a in answers[:3]:
            self.assertEqual(a["type"], "error")
            self.assertEqual(a["code"], "too_deep")
            self.assertNotIn("op", a)
            self.assertLess(len(json.dumps(a)), 1000)
        self.assertEqual(answers[3]["code"], "invalid")
        self.assertNotIn("op", answers[3])
        self.assertEqual(answers[4].get("op"), 7, answers[4])  # a short op is echoed
        self.alive()

    def test_scenes_naming_missing_vertices_or_huge_coordinates_are_400_naming_the_field(self):
        with open(COMPOSITE) as f:
            composite = json.load(f)
        with open(os.path.join(ROOT, "examples", "strip-twisted.json")) as f:
            strip = json.load(f)
        cases = []
        for v in (231, 2147483648):
            bad = json.loads(json.dumps(composite))
            bad["model"]["edges"][0]["v"] = [2, v]
            cases.append((bad, "model.edges[0].v[1]"))
        bad = json.loads(json.dumps(strip))
        bad["model"]["b"]["points"][3][2] = 1e200
        cases.append((bad, "model.b.points[3][2]"))
        for scene, path in cases:
            for route in ("/api/sessions", "/api/jobs"):
                status, _, body = self.daemon.json("POST", route, scene)
                self.assertEqual(status, 400, (route, body))
                self.assertEqual(body["error"]["path"], path, body)
        deep = '{"format":"devsurf-scene","version":1,"model":' + "[" * 50000 + "]" * 50000 + "}"
        status, _, _ = self.daemon.request("POST", "/api/sessions", deep.encode(), {"Content-Type": "application/json"})
        self.assertEqual(status, 400)
        self.alive()

    def test_a_drag_to_a_far_away_position_is_refused_and_the_session_keeps_working(self):
        with open(DEMO) as f:
            scene = json.load(f)
        status, _, s = self.daemon.json("POST", "/api/sessions", scene)
        self.assertEqual(status, 201, s)

        async def run():
            ws, state = await join(self.daemon.port, s["id"], s["edit_token"])
            errors = []
            for op, position in ((1, [1e200, 0, 0]), (2, [0, 1e6, 0])):
                await ws.send(json.dumps({"type": "drag", "op": op, "target": {"curve": "b", "index": 2}, "position": position}))
                errors.append((await recv_until(ws, lambda m: m["type"] == "error"))[-1])
            await ws.send(drag(3, 0.8))
            await ws.send(json.dumps({"type": "drag_end", "op": 4, "target": {"curve": "b", "index": 6}}))
            solved = (await recv_until(ws, lambda m: m["type"] == "solved"))[-1]
            await ws.close()
            return errors, solved

        errors, solved = asyncio.run(run())
        for e in errors:
            self.assertEqual(e["path"], "position", e)
            self.assertIn("model's size", e["message"])
        self.assertTrue(all(v is not None for v in solved["metrics"].values()), solved)
        status, _, body = self.daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
        self.assertEqual(status, 200)
        flat = json.dumps(body["scene"])
        self.assertNotIn("null", flat)
        self.alive()


class ApiKeyTest(DaemonTestCase):
    """With --api-key every job route needs it, not only the submission."""
    PREFIX = "devsurf-key-"
    DAEMON_ARGS = ("--api-key", "k" * 32)

    def test_every_job_route_needs_the_key(self):
        key = {"Authorization": "Bearer " + "k" * 32}
        with open(DEMO) as f:
            scene = json.load(f)
        status, _, body = self.daemon.json("POST", "/api/jobs", scene)
        self.assertEqual(status, 401)
        status, _, body = self.daemon.json("POST", "/api/jobs", scene, key)
        self.assertEqual(status, 202, body)
        job = body["id"]
        for method, path in (("GET", f"/api/jobs/{job}"), ("GET", f"/api/jobs/{job}/result"),
                             ("POST", f"/api/jobs/{job}/cancel")):
            status, _, body = self.daemon.json(method, path)
            self.assertEqual(status, 401, (method, path, body))
            self.assertEqual(body["error"]["code"], "unauthorized")
        status, _, body = self.daemon.json("GET", f"/api/jobs/{job}", headers=key)
        self.assertEqual(status, 200, body)
        # HTTP's authentication schemes are case-insensitive; the token is not.
        status, _, body = self.daemon.json("GET", f"/api/jobs/{job}", headers={"Authorization": "bearer  " + "k" * 32})
        self.assertEqual(status, 200, body)
        status, _, body = self.daemon.json("GET", f"/api/jobs/{job}", headers={"Authorization": "Bearer " + "K" * 32})
        self.assertEqual(status, 401, body)


def raw_ws(port):
    """A WebSocket opened by hand, so that frames the websockets library refuses to send (invalid
    UTF-8 in a text frame) can be sent."""
    import base64
    import socket
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall((f"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                  f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
    head = b""
    while b"\r\n\r\n" not in head:
        head += sock.recv(1)
    assert b" 101 " in head.split(b"\r\n")[0], head
    return sock


def send_frame(sock, payload, opcode=0x1):
    mask = os.urandom(4)
    header = bytes([0x80 | opcode])
    n = len(payload)
    if n < 126:
        header += bytes([0x80 | n])
    elif n < 65536:
        header += bytes([0x80 | 126]) + n.to_bytes(2, "big")
    else:
        header += bytes([0x80 | 127]) + n.to_bytes(8, "big")
    sock.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))


def read_frame(sock):
    def exact(n):
        out = b""
        while len(out) < n:
            chunk = sock.recv(n - len(out))
            if not chunk:
                raise ConnectionError("closed")
            out += chunk
        return out
    b0, b1 = exact(2)
    n = b1 & 0x7F
    if n == 126:
        n = int.from_bytes(exact(2), "big")
    elif n == 127:
        n = int.from_bytes(exact(8), "big")
    return b0 & 0x0F, exact(n)


class BadInputAnswersTest(DaemonTestCase):
    """Issue 12, 'correct answers to bad input': every client error is a 4xx or an error message
    naming the field — never a 500, never silence — and every error is counted."""
    PREFIX = "devsurf-badinput-"

    def test_bodies_that_are_not_scenes_are_400_naming_the_field(self):
        cases = [(b"[]", None), (b"5", None), (b"null", None), (b'"scene"', None),
                 (json.dumps({"format": "devsurf-scene", "version": 1, "solver": {"iterations": "10"}}).encode(), None)]
        with open(DEMO) as f:
            strip = json.load(f)
        for solver, path in ((5, "solver"), ({"iterations": "10"}, "solver.iterations"),
                             ({"iterations": 1e300}, "solver.iterations")):
            strip["solver"] = solver
            cases.append((json.dumps(strip).encode(), path))
        for body, path in cases:
            for route in ("/api/sessions", "/api/jobs"):
                status, _, raw = self.daemon.request("POST", route, body, {"Content-Type": "application/json"})
                self.assertEqual(status, 400, (route, body[:80], raw[:300]))
                answer = json.loads(raw)
                self.assertEqual(answer["error"]["code"], "invalid", answer)
                if path:
                    self.assertEqual(answer["error"]["path"], path, answer)

    def test_a_route_that_does_not_exist_answers_a_json_error_naming_method_and_path(self):
        # A method a path does not take: 405 with the methods it does take, as the OpenAPI
        # document lists them (it was a 404).
        for method, path, allowed in (("PUT", "/api/jobs", "POST"), ("GET", "/api/imports", "POST"),
                                      ("DELETE", "/api/health", "GET"), ("POST", "/api/sessions/abc", "DELETE, GET"),
                                      ("GET", "/api/jobs/abc/cancel", "POST")):
            status, headers, raw = self.daemon.request(method, path)
            self.assertEqual(status, 405, (method, path, raw[:200]))
            self.assertEqual(headers.get("Allow"), allowed, (method, path, headers))
            error = json.loads(raw)["error"]
            self.assertEqual(error["code"], "method_not_allowed", error)
            self.assertIn(method + " ", error["message"])
        # Unknown paths, an id no route pattern matches: each a 404 in the API's error form (it
        # was a 404 with an empty body), and the daemon works on.
        for method, path in (("GET", "/api/jobs/1'%20OR%201=1"), ("GET", "/api/no-such-thing")):
            status, headers, raw = self.daemon.request(method, path)
            self.assertEqual(status, 404, (method, path, raw[:200]))
            self.assertTrue(headers.get("Content-Type", "").startswith("application/json"), (method, path, headers))
            error = json.loads(raw)["error"]
            self.assertEqual(error["code"], "not_found", error)
            self.assertIn(method + " ", error["message"])
            self.assertIn("/api/openapi.json", error["message"])
        # An error a route answers keeps its own body.
        status, _, body = self.daemon.json("GET", "/api/jobs/nope")
        self.assertEqual(status, 404)
        self.assertNotIn("no route answers", body["error"]["message"])
        self.assertEqual(self.daemon.json("GET", "/api/health")[0], 200)

    def test_invalid_utf8_in_a_body_is_400_invalid_json_in_valid_json_without_the_bytes(self):
        body = b'{"format":"devsurf-scene","version":1,"name":"\xff\xfe' + b"A" * 5000 + b'"}'
        for route in ("/api/sessions", "/api/jobs"):
            status, _, raw = self.daemon.request("POST", route, body, {"Content-Type": "application/json"})
            self.assertEqual(status, 400, raw[:300])
            answer = json.loads(raw.decode("utf-8"))  # the answer itself is valid UTF-8 JSON
            self.assertEqual(answer["error"]["code"], "invalid_json")
            self.assertLess(len(raw), 600, "the error must not echo the input")

    def test_a_text_frame_that_is_not_utf8_gets_a_clear_answer(self):
        sock = raw_ws(self.daemon.port)
        try:
            send_frame(sock, b'{"type":"ping","op":"\xff\xfe"}')
            opcode, payload = read_frame(sock)
            if opcode == 0x8:  # close: RFC 6455 §8.1 — 1007, invalid frame payload data
                self.assertEqual(int.from_bytes(payload[:2], "big"), 1007, payload)
            else:
                answer = json.loads(payload.decode("utf-8"))
                self.assertEqual((answer["type"], answer["code"]), ("error", "invalid_json"), answer)
        finally:
            sock.close()
        status, _, body = self.daemon.json("GET", "/api/health")
        self.assertEqual(status, 200)

    def test_a_long_invalid_string_is_answered_without_echoing_it(self):
        async def run():
            ws = await websockets.connect(f"ws://127.0.0.1:{self.daemon.port}/ws", max_size=None)
            await ws.send('{"type":"ping","op":"' + "x" * 200000 + '\\q"}')
            answer = json.loads(await asyncio.wait_for(ws.recv(), 10))
            await ws.close()
            return answer
        answer = asyncio.run(run())
        self.assertEqual(answer["code"], "invalid_json")
        self.assertLess(len(json.dumps(answer)), 600)

    def test_every_error_is_counted_by_code(self):
        def counts():
            _, _, raw = self.daemon.request("GET", "/api/metrics")
            out = {}
            for line in raw.decode().splitlines():
                m = re.match(r'devsurf_errors_total\{code="([a-z_0-9]+)"\} (\d+)', line)
                if m:
                    out[m.group(1)] = int(m.group(2))
            return out
        before = counts()

        async def run():
            ws = await websockets.connect(f"ws://127.0.0.1:{self.daemon.port}/ws", max_size=None)
            await ws.send("{not json")
            await ws.recv()
            await ws.send(json.dumps({"type": "drag"}))
            await ws.recv()
            await ws.close()
        asyncio.run(run())
        self.daemon.request("POST", "/api/sessions", b"{oops", {"Content-Type": "application/json"})
        status, _, _ = self.daemon.request("GET", "/api/health", headers={f"X-F{i}": "1" for i in range(300)})
        self.assertEqual(status, 431)  # answered by the transport before any route: counted too
        after = counts()
        self.assertEqual(after.get("too_large", 0) - before.get("too_large", 0), 1, after)
        self.assertEqual(after.get("invalid_json", 0) - before.get("invalid_json", 0), 2, after)
        self.assertGreaterEqual(after.get("invalid", 0) - before.get("invalid", 0), 1, after)


class TokensNeverLoggedTest(unittest.TestCase):
    """Issue 12: tokens and the API key are stored as SHA-256 hashes and never written to the log,
    even at the most verbose level; the store file holds none of them either."""

    def test_no_token_appears_in_the_trace_log_or_the_store(self):
        import subprocess
        tmp = tempfile.mkdtemp(prefix="devsurf-tokens-")
        log_path = os.path.join(tmp, "daemon.log")
        key = "k" + os.urandom(16).hex()
        try:
            with open(log_path, "w") as log:
                proc = subprocess.Popen([BIN, "serve", "--port", "0", "--data", os.path.join(tmp, "data"),
                                         "--api-key", key, "--log-level", "trace"],
                                        stdout=subprocess.PIPE, stderr=log, text=True)
                line = proc.stdout.readline()
                port = int(re.search(r":(\d+)/", line).group(1))
                daemon = Daemon(tmp)
                daemon.port = port
                with open(DEMO) as f:
                    scene = json.load(f)
                auth = {"Authorization": "Bearer " + key}
                status, _, s = daemon.json("POST", "/api/sessions", scene, auth)
                self.assertEqual(status, 201, s)
                secrets = [key, s["edit_token"], s["view_token"]]

                async def run():
                    ws, state = await join(port, s["id"], s["edit_token"])
                    await ws.send(drag(1, 0.7))
                    await ws.send(json.dumps({"type": "drag_end", "op": 2, "target": {"curve": "b", "index": 6}}))
                    await recv_until(ws, lambda m: m["type"] == "solved", timeout=30)
                    await ws.close()
                    bad = await websockets.connect(f"ws://127.0.0.1:{port}/ws")
                    await bad.send(json.dumps({"type": "join", "session": s["id"], "token": "f" * 32}))
                    await bad.recv()
                asyncio.run(run())
                daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
                daemon.json("GET", f"/api/sessions/{s['id']}?token={s['edit_token']}")
                daemon.json("POST", "/api/jobs", scene, auth)
                daemon.json("GET", "/api/jobs/nope", headers={"Authorization": "Bearer wrong-" + key})
                proc.send_signal(signal.SIGTERM)
                self.assertEqual(proc.wait(timeout=30), 0)
                proc.stdout.close()
            with open(log_path, errors="replace") as f:
                log_text = f.read()
            self.assertGreater(len(log_text.splitlines()), 5, "the trace log should say something")
            for secret in secrets:
                self.assertNotIn(secret, log_text)
            stored = b""
            for name in os.listdir(os.path.join(tmp, "data")):
                with open(os.path.join(tmp, "data", name), "rb") as f:
                    stored += f.read()
            for secret in secrets:
                self.assertNotIn(secret.encode(), stored)
            self.assertIn(hashlib.sha256(s["edit_token"].encode()).hexdigest().encode(), stored)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
