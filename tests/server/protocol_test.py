"""End-to-end tests of `devsurf serve` with an independent client: Python's websockets (Debian's
python3-websockets) and urllib. Each test class starts its own daemon on an ephemeral port.

Run: /usr/bin/python3 -m unittest tests/server/protocol_test.py   (DEVSURF_BIN = path of devsurf)
"""
import asyncio
import json
import os
import random
import re
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
import urllib.error
import urllib.request

import websockets

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("DEVSURF_BIN", os.path.join(ROOT, "build", "server", "devsurf"))
DEMO = os.path.join(ROOT, "examples", "strip-lifted-corner.json")
COMPOSITE = os.path.join(ROOT, "examples", "composite-curved-fold.json")
QUASI = os.path.join(ROOT, "examples", "quasi-strip-twisted.json")
CONICAL = os.path.join(ROOT, "examples", "conical-strip-hull.json")


class Daemon:
    def __init__(self, data_dir, *extra):
        self.data_dir = data_dir
        self.extra = list(extra)
        self.proc = None
        self.port = None

    def start(self):
        self.proc = subprocess.Popen(
            [BIN, "serve", "--port", "0", "--data", self.data_dir, "--demo", DEMO, *self.extra],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        m = re.search(r":(\d+)/", line)
        if not m:
            raise RuntimeError("daemon did not start: " + line)
        self.port = int(m.group(1))
        return self

    def kill(self):
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait()
        self.proc.stdout.close()

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            self.proc.wait(timeout=20)
            self.proc.stdout.close()
        return self.proc.returncode

    def url(self, path):
        return f"http://127.0.0.1:{self.port}{path}"

    def request(self, method, path, body=None, headers=None):
        data = None if body is None else (body if isinstance(body, bytes) else json.dumps(body).encode())
        headers = dict(headers or {})
        if data is not None:
            headers.setdefault("Content-Type", "application/json")
        req = urllib.request.Request(self.url(path), data=data, method=method, headers=headers)
        try:
            with urllib.request.urlopen(req, timeout=30) as r:
                return r.status, dict(r.headers), r.read()
        except urllib.error.HTTPError as e:
            return e.code, dict(e.headers), e.read()

    def json(self, method, path, body=None, headers=None):
        status, h, raw = self.request(method, path, body, headers)
        return status, h, (json.loads(raw) if raw else None)


async def recv_until(ws, predicate, timeout=20.0):
    """Messages up to and including the first one that satisfies predicate."""
    seen = []
    deadline = time.monotonic() + timeout
    while True:
        m = json.loads(await asyncio.wait_for(ws.recv(), deadline - time.monotonic()))
        seen.append(m)
        if predicate(m):
            return seen


async def join(port, session, token, name="py"):
    ws = await websockets.connect(f"ws://127.0.0.1:{port}/ws", max_size=None)
    await ws.send(json.dumps({"type": "join", "session": session, "token": token, "name": name}))
    state = json.loads(await ws.recv())
    return ws, state


def drag(op, z, index=6):
    return json.dumps({"type": "drag", "op": op, "target": {"curve": "b", "index": index}, "position": [6.0, 1.0, z]})


class DaemonTestCase(unittest.TestCase):
    """One daemon per test class, started with DAEMON_ARGS in a fresh data directory and stopped
    with SIGTERM (which must exit 0)."""

    DAEMON_ARGS = ()
    PREFIX = "devsurf-proto-"

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix=cls.PREFIX)
        cls.daemon = Daemon(cls.tmp, *cls.DAEMON_ARGS).start()

    @classmethod
    def tearDownClass(cls):
        code = cls.daemon.stop()
        assert code == 0, f"devsurf serve exited with {code} on SIGTERM"
        shutil.rmtree(cls.tmp, ignore_errors=True)


class ProtocolTest(DaemonTestCase):
    PREFIX = "devsurf-proto-"
    DAEMON_ARGS = ("--max-message", "65536")

    def new_session(self):
        with open(DEMO) as f:
            scene = json.load(f)
        scene["model"].pop("handles", None)
        status, headers, body = self.daemon.json("POST", "/api/sessions", scene)
        self.assertEqual(status, 201, body)
        self.assertTrue(headers["Location"].endswith(body["id"]))
        self.assertEqual(len(body["edit_token"]), 32)
        return body

    def test_drag_streams_iterates_until_the_strip_is_developable(self):
        s = self.new_session()

        async def run():
            ws, state = await join(self.daemon.port, s["id"], s["edit_token"])
            self.assertEqual(state["type"], "state")
            self.assertEqual(state["role"], "edit")
            for k in range(1, 7):
                await ws.send(drag(k, 0.3 * k))
                await asyncio.sleep(0.02)
            await ws.send(json.dumps({"type": "drag_end", "op": "end", "target": {"curve": "b", "index": 6}}))
            seen = await recv_until(ws, lambda m: m["type"] == "solved")
            await ws.close()
            return seen

        seen = asyncio.run(run())
        acks = [m for m in seen if m["type"] == "ack"]
        self.assertEqual({a["op"] for a in acks}, {1, 2, 3, 4, 5, 6, "end"})
        seqs = [a["seq"] for a in acks]
        self.assertEqual(seqs, sorted(seqs))
        iterates = [m for m in seen if m["type"] == "iterate"]
        self.assertGreaterEqual(len(iterates), 3)
        final = [m for m in iterates if m["seq"] == seen[-1]["seq"]]
        self.assertLess(final[-1]["metrics"]["warp_angle_max_deg"], 0.05)
        self.assertLess(seen[-1]["metrics"]["warp_angle_max_deg"], 0.05)
        geometry = iterates[-1]["geometry"]
        self.assertEqual(geometry["surface"]["vertices"]["dtype"], "float32")
        status, _, body = self.daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
        self.assertEqual(status, 200)
        self.assertAlmostEqual(body["scene"]["model"]["b"]["points"][6][2], 1.8, delta=0.05)

    def test_two_clients_see_each_others_edits_and_presence(self):
        s = self.new_session()

        async def run():
            a, _ = await join(self.daemon.port, s["id"], s["edit_token"], "ada")
            b, state_b = await join(self.daemon.port, s["id"], s["edit_token"], "bob")
            names = lambda m: sorted(p["name"] for p in m["participants"])
            await recv_until(a, lambda m: m["type"] == "presence" and names(m) == ["ada", "bob"])
            await b.send(json.dumps({"type": "presence", "selection": {"curve": "a", "index": 2}}))
            seen = await recv_until(a, lambda m: m["type"] == "presence" and any(p["selection"] for p in m["participants"]))
            await b.send(json.dumps({"type": "set_fixed", "op": 1, "target": {"curve": "a", "index": 6}, "fixed": True}))
            edit = await recv_until(a, lambda m: m["type"] == "edit")
            update = await recv_until(a, lambda m: m["type"] == "update")
            await a.close()
            await b.close()
            return seen[-1], edit[-1], update[-1]

        presence, edit, update = asyncio.run(run())
        selection = [p for p in presence["participants"] if p["name"] == "bob"][0]["selection"]
        self.assertEqual(selection, {"curve": "a", "index": 2})
        self.assertEqual(edit["edit"]["type"], "set_fixed")
        self.assertIn({"curve": "a", "index": 6}, update["scene"]["model"]["fixed"])

    def test_view_only_client_watches_but_cannot_edit(self):
        s = self.new_session()

        async def run():
            v, state = await join(self.daemon.port, s["id"], s["view_token"])
            self.assertEqual(state["role"], "view")
            await v.send(drag("v1", 1.0))
            err = await recv_until(v, lambda m: m["type"] == "error")
            e, _ = await join(self.daemon.port, s["id"], s["edit_token"])
            await e.send(drag("e1", 1.0))
            it = await recv_until(v, lambda m: m["type"] == "iterate")
            await v.close()
            await e.close()
            return err[-1], it[-1]

        err, iterate = asyncio.run(run())
        self.assertEqual(err["code"], "forbidden")
        self.assertEqual(err["op"], "v1")
        self.assertEqual(iterate["type"], "iterate")

    def test_bad_messages_get_clear_errors_and_the_daemon_keeps_serving(self):
        s = self.new_session()

        async def run():
            ws, _ = await join(self.daemon.port, s["id"], s["edit_token"])
            errors = []
            for text in ["{not json",
                         json.dumps({"type": "drag", "op": 1, "target": {"curve": "b", "index": "six"}, "position": [0, 0, 0]}),
                         json.dumps({"type": "teleport", "op": 2}),
                         json.dumps({"type": "drag", "op": 3, "target": {"curve": "b", "index": 99}, "position": [0, 0, 0]}),
                         json.dumps({"type": "drag", "op": 4, "target": {"curve": "b", "index": 2}, "position": [0, 0]}),
                         json.dumps({"type": "solve", "op": 5, "iterations": 1e9}),
                         json.dumps({"type": "presence", "selection": None, "name": "x" * 100000})]:
                await ws.send(text)
                errors.append((await recv_until(ws, lambda m: m["type"] == "error"))[-1])
            await ws.send(json.dumps({"type": "ping", "op": "still-there"}))
            pong = await recv_until(ws, lambda m: m["type"] == "pong")
            await ws.close()
            # A wrong token closes the connection after the error.
            bad = await websockets.connect(f"ws://127.0.0.1:{self.daemon.port}/ws")
            await bad.send(json.dumps({"type": "join", "session": s["id"], "token": "0" * 32}))
            unauthorized = json.loads(await bad.recv())
            closed = False
            try:
                await asyncio.wait_for(bad.recv(), 5)
            except websockets.ConnectionClosed:
                closed = True
            return errors, pong[-1], unauthorized, closed

        errors, pong, unauthorized, closed = asyncio.run(run())
        self.assertEqual(errors[0]["code"], "invalid_json")
        self.assertEqual(errors[1]["path"], "target.index")
        self.assertEqual(errors[2]["path"], "type")
        self.assertIn("unknown", errors[2]["message"])
        self.assertEqual(errors[3]["path"], "target.index")
        self.assertEqual(errors[4]["path"], "position")
        self.assertEqual(errors[5]["path"], "iterations")
        self.assertEqual(errors[6]["code"], "too_large")
        self.assertEqual(pong["op"], "still-there")
        self.assertEqual(unauthorized["code"], "unauthorized")
        self.assertTrue(closed)
        status, _, body = self.daemon.json("GET", "/api/health")
        self.assertEqual((status, body["status"]), (200, "ok"))

    def test_rest_sessions_tokens_export_and_delete(self):
        s = self.new_session()
        auth = lambda t: {"Authorization": "Bearer " + t}
        self.assertEqual(self.daemon.json("GET", f"/api/sessions/{s['id']}", headers=auth("nope"))[0], 404)
        status, _, body = self.daemon.json("GET", f"/api/sessions/{s['id']}", headers=auth(s["view_token"]))
        self.assertEqual(status, 200)
        self.assertEqual(body["scene"]["format"], "devsurf-scene")
        status, _, raw = self.daemon.request("GET", f"/api/sessions/{s['id']}/export?format=obj", headers=auth(s["view_token"]))
        self.assertEqual(status, 200)
        self.assertEqual(raw.decode().count("\nf "), 199 * 7)
        self.assertEqual(self.daemon.json("GET", f"/api/sessions/{s['id']}/export?format=step", headers=auth(s["view_token"]))[0], 400)
        self.assertEqual(self.daemon.json("DELETE", f"/api/sessions/{s['id']}", headers=auth(s["view_token"]))[0], 403)
        self.assertEqual(self.daemon.request("DELETE", f"/api/sessions/{s['id']}", headers=auth(s["edit_token"]))[0], 204)
        self.assertEqual(self.daemon.json("GET", f"/api/sessions/{s['id']}", headers=auth(s["edit_token"]))[0], 404)
        # Malformed bodies.
        status, _, body = self.daemon.json("POST", "/api/sessions", b"{oops")
        self.assertEqual((status, body["error"]["code"]), (400, "invalid_json"))
        status, _, body = self.daemon.json("POST", "/api/sessions", {"format": "devsurf-scene", "version": 1, "model": {"kind": "sphere"}})
        self.assertEqual((status, body["error"]["path"]), (400, "model.kind"))
        demos = self.daemon.json("GET", "/api/sessions")[2]["sessions"]
        self.assertEqual(demos[0]["id"], "demo-strip-lifted-corner")

    def test_job_lifecycle_with_idempotency_and_cancel(self):
        with open(os.path.join(ROOT, "examples", "strip-twisted.json")) as f:
            scene = json.load(f)
        status, headers, body = self.daemon.json("POST", "/api/jobs", scene, {"Idempotency-Key": "k1"})
        self.assertEqual(status, 202)
        job = body["id"]
        self.assertEqual(headers["Location"], "/api/jobs/" + job)
        status, _, again = self.daemon.json("POST", "/api/jobs", scene, {"Idempotency-Key": "k1"})
        self.assertEqual((status, again["id"]), (200, job))
        other = dict(scene, name="another")
        self.assertEqual(self.daemon.json("POST", "/api/jobs", other, {"Idempotency-Key": "k1"})[0], 422)
        for _ in range(300):
            status, headers, body = self.daemon.json("GET", "/api/jobs/" + job)
            if body["state"] == "succeeded":
                break
            self.assertIn("Retry-After", headers)
            time.sleep(0.05)
        self.assertEqual(body["state"], "succeeded")
        self.assertLess(body["report"]["metrics"]["warp_angle_max_deg"], 0.05)
        status, _, raw = self.daemon.request("GET", f"/api/jobs/{job}/result?format=obj")
        self.assertEqual(status, 200)
        self.assertTrue(raw.startswith(b"# "))
        self.assertEqual(self.daemon.json("POST", f"/api/jobs/{job}/cancel")[0], 409)
        # A long job is cancelled while running.
        long = json.loads(json.dumps(scene))
        long["solver"] = {"iterations": 10000, "residual_tolerance": 0, "relative_change_tolerance": 0}
        n = 300
        long["model"]["a"]["points"] = [[i * 0.02, 0, 0] for i in range(n)]
        long["model"]["b"]["points"] = [[i * 0.02, 1, 0.001 * i] for i in range(n)]
        long["model"]["fixed"] = [{"curve": "a", "index": 0}]
        job2 = self.daemon.json("POST", "/api/jobs", long)[2]["id"]
        time.sleep(0.3)
        self.assertEqual(self.daemon.json("POST", f"/api/jobs/{job2}/cancel")[0], 202)
        for _ in range(200):
            state = self.daemon.json("GET", "/api/jobs/" + job2)[2]["state"]
            if state == "cancelled":
                break
            time.sleep(0.05)
        self.assertEqual(state, "cancelled")
        self.assertEqual(self.daemon.json("GET", "/api/jobs/nope")[0], 404)

    def test_openapi_lists_every_route_and_metrics_are_prometheus_text(self):
        status, _, doc = self.daemon.json("GET", "/api/openapi.json")
        self.assertEqual(status, 200)
        self.assertEqual(doc["openapi"], "3.1.0")
        routes = {"/api/health", "/api/metrics", "/api/openapi.json", "/api/sessions", "/api/sessions/{id}",
                  "/api/sessions/{id}/export", "/api/jobs", "/api/jobs/{id}", "/api/jobs/{id}/cancel",
                  "/api/jobs/{id}/result", "/ws"}
        self.assertEqual(set(doc["paths"]), routes)
        # Every route the server registers answers (not 404 from an unknown route).
        with open(os.path.join(ROOT, "server", "src", "Daemon.cpp")) as f:
            source = f.read()
        registered = set(re.findall(r's\.(?:Get|Post|Delete)\("([^"]+)"', source))
        registered |= {re.sub(r"\(\[A-Za-z0-9_-\]\+\)", "{id}", r) for r in re.findall(r's\.(?:Get|Post|Delete)\(R"\(([^)]*\)[^)]*)\)"', source)}
        self.assertTrue(registered <= routes, registered - routes)
        status, headers, raw = self.daemon.request("GET", "/api/metrics")
        self.assertEqual(status, 200)
        text = raw.decode()
        for name in ["devsurf_sessions", "devsurf_clients", "devsurf_jobs{state=\"queued\"}", "devsurf_iterations_total",
                     "devsurf_iteration_seconds_bucket{le=\"+Inf\"}", "devsurf_iteration_seconds_count"]:
            self.assertIn(name, text)
        # Every operation of the OpenAPI document is well formed.
        for path, item in doc["paths"].items():
            for method, operation in item.items():
                self.assertIn(method, {"get", "post", "delete"}, path)
                self.assertIn("responses", operation, f"{method} {path}")
                self.assertTrue(all(re.fullmatch(r"\d{3}", code) for code in operation["responses"]), f"{method} {path}")

    def test_job_submit_cli_waits_for_the_report(self):
        out = subprocess.run([BIN, "job", "submit", os.path.join(ROOT, "examples", "strip-cone.json"),
                              "--server", f"http://127.0.0.1:{self.daemon.port}", "--wait"],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        report = json.loads(out.stdout)
        self.assertEqual(report["format"], "devsurf-report")
        self.assertLess(report["metrics"]["warp_angle_max_deg"], 1e-9)
        bad = subprocess.run([BIN, "job", "submit", DEMO, "--server", "http://127.0.0.1:1"],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(bad.returncode, 1)
        self.assertIn("cannot reach", bad.stderr)


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


class RestartTest(unittest.TestCase):
    def test_sigkill_at_random_moments_loses_no_acknowledged_edit(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-kill-")
        rng = random.Random(7)
        try:
            daemon = Daemon(tmp).start()
            demo = daemon.json("GET", "/api/sessions")[2]["sessions"][0]
            daemon.kill()
            expected = {}  # seq → z of the handle that edit set
            sent = 0
            trials = 20
            for trial in range(trials):
                daemon = Daemon(tmp).start()
                status, _, body = daemon.json("GET", f"/api/sessions/{demo['id']}", headers={"Authorization": "Bearer " + demo["view_token"]})
                self.assertEqual(status, 200)
                restored_seq = body["seq"]
                acked = max(expected) if expected else 0
                self.assertGreaterEqual(restored_seq, acked, f"trial {trial}: acked edits lost")
                if restored_seq in expected:
                    handles = body["scene"]["model"].get("handles", [])
                    z = [h["position"][2] for h in handles if h["curve"] == "a" and h["index"] == 6]
                    self.assertEqual(z, [expected[restored_seq]], f"trial {trial}: seq {restored_seq}")
                # Unacknowledged edits that became durable are kept too: adopt the daemon's count.
                next_seq = restored_seq

                async def edit_until_killed():
                    nonlocal next_seq, sent
                    ws, state = await join(daemon.port, demo["id"], demo["edit_token"])
                    assert state["seq"] == restored_seq
                    pending = {}
                    kill_at = time.monotonic() + rng.uniform(0.05, 0.4)
                    try:
                        while time.monotonic() < kill_at:
                            sent += 1
                            z = round(0.001 * sent, 6)
                            await ws.send(json.dumps({"type": "add_handle", "op": sent, "target": {"curve": "a", "index": 6}, "position": [5.5, 0, z]}))
                            pending[sent] = z
                            m = json.loads(await asyncio.wait_for(ws.recv(), 5))
                            while m["type"] != "ack":
                                m = json.loads(await asyncio.wait_for(ws.recv(), 5))
                            expected[m["seq"]] = pending.pop(m["op"])
                        daemon.kill()
                    finally:
                        try:
                            await ws.close()
                        except Exception:
                            pass

                asyncio.run(edit_until_killed())
            self.assertGreater(len(expected), trials)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


def numbers(x):
    """Every number of a JSON value, in document order."""
    if isinstance(x, bool) or x is None:
        return []
    if isinstance(x, (int, float)):
        return [float(x)]
    if isinstance(x, list):
        return [v for e in x for v in numbers(e)]
    if isinstance(x, dict):
        return [v for k in sorted(x) for v in numbers(x[k])]
    return []


class ExactRestoreTest(unittest.TestCase):
    """Issue 12: after SIGKILL a restart restores the state clients read at the last acknowledged
    seq, not a re-solve of the journal (releases run under time budgets, so a replay differs)."""

    CASES = (("strip-lifted-corner.json", {"curve": "b", "index": 6}),
             ("composite-curved-fold.json", {"vertex": 3}),
             ("quasi-strip-twisted.json", {"curve": "c1", "index": 2}),
             ("conical-strip-hull.json", {"curve": "p", "index": 1}))

    @staticmethod
    def point(model, target):
        if "vertex" in target:
            return model["vertices"][target["vertex"]]
        return model[target["curve"]]["points"][target["index"]]

    def test_sigkill_after_each_release_restores_every_coordinate(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-exact-")
        try:
            daemon = Daemon(tmp).start()
            sessions = []
            for name, target in self.CASES:
                with open(os.path.join(ROOT, "examples", name)) as f:
                    status, _, body = daemon.json("POST", "/api/sessions", json.load(f))
                self.assertEqual(status, 201, body)
                sessions.append((name, target, body))
            for round_ in range(3):
                seen = {}
                for name, target, s in sessions:
                    async def edit():
                        ws, state = await join(daemon.port, s["id"], s["edit_token"])
                        model = state["scene"]["model"]
                        p = self.point(model, target)
                        xs = numbers(model)
                        size = max(xs) - min(xs)
                        for k in range(1, 4):
                            q = [p[0] + 0.02 * size * k, p[1] - 0.01 * size * k, p[2] + 0.03 * size * k]
                            await ws.send(json.dumps({"type": "drag", "op": k, "target": target, "position": q}))
                        await ws.send(json.dumps({"type": "drag_end", "op": 9, "target": target}))
                        await recv_until(ws, lambda m: m["type"] == "solved", timeout=60)
                        await ws.close()
                        return size

                    size = asyncio.run(edit())
                    status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
                    self.assertEqual(status, 200)
                    seen[name] = (body["seq"], body["scene"]["model"], size)
                daemon.kill()
                daemon = Daemon(tmp).start()
                for name, target, s in sessions:
                    status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
                    self.assertEqual(status, 200, f"round {round_}: {name} was not restored")
                    seq, model, size = seen[name]
                    self.assertEqual(body["seq"], seq, f"round {round_}: {name}")
                    before, after = numbers(model), numbers(body["scene"]["model"])
                    self.assertEqual(len(before), len(after), f"round {round_}: {name}")
                    diffs = [abs(a - b) for a, b in zip(before, after)]
                    worst = max(diffs)
                    keys = [k for k in sorted(model) if model[k] != body["scene"]["model"].get(k)]
                    self.assertLessEqual(worst, 1e-12 * size,
                                         f"round {round_}: {name} restored {worst} away (number {diffs.index(worst)}; members {keys})")
            daemon.stop()
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


class CurveStripProtocolTest(DaemonTestCase):
    """Sessions of the strips between two given curves (issue 6): quasi_strip (Bo et al.) and
    conical_strip (Chu et al.) demos; drags move an input curve's control point, the strip is
    rebuilt and solved whole."""

    PREFIX = "devsurf-proto-curves-"
    DAEMON_ARGS = ("--demo", QUASI, "--demo", CONICAL)

    def new_session(self, path):
        with open(path) as f:
            scene = json.load(f)
        status, _, body = self.daemon.json("POST", "/api/sessions", scene)
        self.assertEqual(status, 201, body)
        return body

    def test_both_demos_are_listed_and_join_with_their_geometry(self):
        demos = {d["id"]: d for d in self.daemon.json("GET", "/api/sessions")[2]["sessions"]}

        async def run(demo):
            ws, state = await join(self.daemon.port, demo["id"], demo["view_token"])
            await ws.close()
            return state

        quasi = asyncio.run(run(demos["demo-quasi-strip-twisted"]))
        self.assertEqual(quasi["geometry"]["kind"], "quasi_strip")
        self.assertEqual(quasi["geometry"]["mapping"]["sigma"]["shape"], quasi["geometry"]["mapping"]["initial"]["shape"])
        self.assertLessEqual(quasi["metrics"]["warp_angle_max_deg"], 2.0)
        conical = asyncio.run(run(demos["demo-conical-strip-hull"]))
        self.assertEqual(conical["geometry"]["kind"], "conical_strip")
        self.assertEqual(conical["geometry"]["patches"]["type"]["dtype"], "int32")
        self.assertGreater(conical["geometry"]["development"]["quads"]["shape"][0], 0)

    def test_dragging_a_control_point_of_c1_resolves_and_release_reports_solved(self):
        s = self.new_session(QUASI)

        async def run():
            ws, state = await join(self.daemon.port, s["id"], s["edit_token"])
            p = state["scene"]["model"]["c1"]["points"][8]
            for k in range(1, 4):
                await ws.send(json.dumps({"type": "drag", "op": k, "target": {"curve": "c1", "index": 8},
                                          "position": [p[0], p[1] + 0.1 * k, p[2]]}))
            await ws.send(json.dumps({"type": "drag_end", "op": "end", "target": {"curve": "c1", "index": 8}}))
            seen = await recv_until(ws, lambda m: m["type"] == "solved")
            await ws.close()
            return p, seen

        p, seen = asyncio.run(run())
        self.assertEqual([m for m in seen if m["type"] == "error"], [])
        self.assertEqual({m["op"] for m in seen if m["type"] == "ack"}, {1, 2, 3, "end"})
        iterates = [m for m in seen if m["type"] == "iterate"]
        self.assertGreaterEqual(len(iterates), 1)
        self.assertIn("warp_angle_max_deg", iterates[-1]["metrics"])
        self.assertEqual(iterates[-1]["geometry"]["kind"], "quasi_strip")
        status, _, body = self.daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
        self.assertAlmostEqual(body["scene"]["model"]["c1"]["points"][8][1], p[1] + 0.3, places=9)

    def test_set_params_is_validated_by_the_schema_and_the_session_naming_the_field(self):
        s = self.new_session(CONICAL)

        async def run():
            ws, _ = await join(self.daemon.port, s["id"], s["edit_token"])
            errors = []
            for message in [{"type": "set_params", "op": 1, "params": {"np": 1}},
                            {"type": "set_params", "op": 2, "params": {"colour": 3}},
                            {"type": "set_params", "op": 3, "params": {"samples": 30}},
                            {"type": "add_handle", "op": 4, "target": {"curve": "p", "index": 0}, "position": [0, 0, 0]},
                            {"type": "drag", "op": 5, "target": {"curve": "c1", "index": 0}, "position": [0, 0, 0]}]:
                await ws.send(json.dumps(message))
                errors.append((await recv_until(ws, lambda m: m["type"] == "error"))[-1])
            await ws.send(json.dumps({"type": "set_params", "op": "ok", "params": {"np": 24, "nq": 26}}))
            update = (await recv_until(ws, lambda m: m["type"] == "update"))[-1]
            await ws.send(json.dumps({"type": "undo", "op": "u"}))
            undone = (await recv_until(ws, lambda m: m["type"] == "update"))[-1]
            await ws.close()
            return errors, update, undone

        errors, update, undone = asyncio.run(run())
        self.assertEqual([e["op"] for e in errors], [1, 2, 3, 4, 5])
        self.assertTrue(errors[0]["path"].startswith("params.np"), errors[0])
        self.assertTrue(errors[1]["path"].startswith("params"), errors[1])
        self.assertEqual(errors[2]["path"], "params.samples")
        self.assertEqual(errors[3]["path"], "type")
        self.assertIn("add_handle", errors[3]["message"])
        self.assertEqual(errors[4]["path"], "target.curve")
        self.assertEqual(update["scene"]["model"]["np"], 24)
        self.assertEqual(update["geometry"]["samples"]["p"]["shape"], [24, 3])
        self.assertNotEqual(undone["scene"]["model"]["np"], 24)

    def test_edits_survive_a_restart_through_the_journal(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-proto-curves-restart-")
        try:
            daemon = Daemon(tmp).start()
            with open(QUASI) as f:
                scene = json.load(f)
            status, _, s = daemon.json("POST", "/api/sessions", scene)
            self.assertEqual(status, 201, s)

            async def run():
                ws, _ = await join(daemon.port, s["id"], s["edit_token"])
                await ws.send(json.dumps({"type": "set_params", "op": 1, "params": {"mapping": {"coefficients": 20}}}))
                await recv_until(ws, lambda m: m["type"] == "ack")
                await ws.send(json.dumps({"type": "drag", "op": 2, "target": {"curve": "c2", "index": 2}, "position": [2.0, -0.7, 1.1]}))
                await recv_until(ws, lambda m: m["type"] == "ack")
                await ws.close()

            asyncio.run(run())
            daemon.kill()
            daemon = Daemon(tmp).start()
            status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
            daemon.stop()
            self.assertEqual(status, 200)
            self.assertEqual(body["seq"], 2)
            self.assertEqual(body["scene"]["model"]["mapping"]["coefficients"], 20)
            self.assertEqual(body["scene"]["model"]["c2"]["points"][2], [2.0, -0.7, 1.1])
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


class CompositeProtocolTest(DaemonTestCase):
    """Composite sessions (examples/composite-curved-fold.json: two strips joined by the curved
    fold edge 0; vertices 0, 1, 4, 5 fixed; a development)."""

    PREFIX = "devsurf-proto-composite-"
    DAEMON_ARGS = ("--demo", COMPOSITE,)

    def new_session(self):
        with open(COMPOSITE) as f:
            scene = json.load(f)
        scene["model"].pop("handles", None)
        status, _, body = self.daemon.json("POST", "/api/sessions", scene)
        self.assertEqual(status, 201, body)
        return body

    def test_the_composite_demo_joins_with_composite_geometry(self):
        demos = {d["id"]: d for d in self.daemon.json("GET", "/api/sessions")[2]["sessions"]}
        self.assertIn("demo-composite-curved-fold", demos)
        demo = demos["demo-composite-curved-fold"]

        async def run():
            ws, state = await join(self.daemon.port, demo["id"], demo["view_token"])
            await ws.close()
            return state

        state = asyncio.run(run())
        self.assertEqual(state["scene"]["model"]["kind"], "composite")
        g = state["geometry"]
        self.assertEqual(g["kind"], "composite")
        self.assertEqual(g["surface"]["quads"]["dtype"], "int32")
        self.assertEqual([e["crease"] for e in g["edges"]][0], "fold")
        self.assertEqual(g["points"]["refs"]["shape"], [18, 3])
        self.assertGreater(g["development"]["triangles"]["shape"][0], 0)
        self.assertIn("face_flatness_max", state["metrics"])

    def test_dragging_a_vertex_streams_iterates_and_release_solves(self):
        s = self.new_session()

        async def run():
            ws, state = await join(self.daemon.port, s["id"], s["edit_token"])
            for k in range(1, 5):
                await ws.send(json.dumps({"type": "drag", "op": k, "target": {"vertex": 3}, "position": [2.0, 2.0, 0.2 * k]}))
                await asyncio.sleep(0.02)
            await ws.send(json.dumps({"type": "drag_end", "op": "end", "target": {"vertex": 3}, "iterations": 30}))
            seen = await recv_until(ws, lambda m: m["type"] == "solved")
            await ws.close()
            return seen

        seen = asyncio.run(run())
        self.assertEqual([m for m in seen if m["type"] == "error"], [])
        self.assertEqual({m["op"] for m in seen if m["type"] == "ack"}, {1, 2, 3, 4, "end"})
        iterates = [m for m in seen if m["type"] == "iterate"]
        self.assertGreaterEqual(len(iterates), 2)
        self.assertEqual(iterates[-1]["geometry"]["kind"], "composite")
        self.assertIn("crease_fold", iterates[-1]["residuals"])
        metrics = seen[-1]["metrics"]
        self.assertLess(metrics["face_flatness_max"], 1e-3)
        self.assertLess(metrics["crease_fold_residual_max"], 1e-3)
        status, _, body = self.daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer " + s["view_token"]})
        self.assertGreater(body["scene"]["model"]["vertices"][3][2], 0.3)

    def test_switching_a_crease_type_is_undoable(self):
        s = self.new_session()

        async def run():
            ws, _ = await join(self.daemon.port, s["id"], s["edit_token"])
            await ws.send(json.dumps({"type": "set_crease", "op": "c1", "edge": 0, "crease": "smooth"}))
            switched = (await recv_until(ws, lambda m: m["type"] == "update"))[-1]
            await ws.send(json.dumps({"type": "undo", "op": "u1"}))
            undone = (await recv_until(ws, lambda m: m["type"] == "update"))[-1]
            await ws.close()
            return switched, undone

        switched, undone = asyncio.run(run())
        self.assertEqual(switched["scene"]["model"]["edges"][0]["crease"], "smooth")
        self.assertEqual(switched["geometry"]["edges"][0]["crease"], "smooth")
        self.assertEqual(undone["scene"]["model"]["edges"][0]["crease"], "fold")
        self.assertEqual(undone["undo"]["redo_available"], 1)

    def test_bad_references_get_errors_naming_the_field(self):
        s = self.new_session()

        async def run():
            ws, _ = await join(self.daemon.port, s["id"], s["edit_token"])
            errors = []
            for message in [{"type": "drag", "op": 1, "target": {"vertex": -1}, "position": [0, 0, 0]},
                            {"type": "drag", "op": 2, "target": {"vertex": 99}, "position": [0, 0, 0]},
                            {"type": "drag", "op": 3, "target": {"edge": 0, "index": 40}, "position": [0, 0, 0]},
                            {"type": "drag", "op": 4, "target": {"curve": "a", "index": 0}, "position": [0, 0, 0]},
                            {"type": "set_crease", "op": 5, "edge": 0, "crease": "crumple"},
                            {"type": "set_crease", "op": 6, "edge": 1, "crease": "fold"}]:
                await ws.send(json.dumps(message))
                errors.append((await recv_until(ws, lambda m: m["type"] == "error"))[-1])
            await ws.close()
            return errors

        errors = asyncio.run(run())
        self.assertEqual([e["path"] for e in errors],
                         ["target.vertex", "target.vertex", "target.index", "target", "crease", "edge"])
        self.assertEqual([e["op"] for e in errors], [1, 2, 3, 4, 5, 6])
        self.assertIn("composite", errors[3]["message"])
        self.assertIn("set_crease", errors[5]["message"])

    def test_rest_exports_fold_svg_and_obj_and_refuses_what_does_not_apply(self):
        s = self.new_session()
        auth = {"Authorization": "Bearer " + s["view_token"]}
        status, headers, raw = self.daemon.request("GET", f"/api/sessions/{s['id']}/export?format=fold", headers=auth)
        self.assertEqual(status, 200)
        fold = json.loads(raw)
        self.assertEqual(fold["file_spec"], 1.2)
        self.assertIn("B", fold["edges_assignment"])
        self.assertEqual(set(fold["edges_assignment"]) - {"B", "M", "V", "F"}, set())
        self.assertIn(".fold", headers["Content-Disposition"])
        status, headers, raw = self.daemon.request("GET", f"/api/sessions/{s['id']}/export?format=svg", headers=auth)
        self.assertEqual(status, 200)
        self.assertTrue(headers["Content-Type"].startswith("image/svg+xml"))
        self.assertIn(b"<svg", raw)
        status, _, raw = self.daemon.request("GET", f"/api/sessions/{s['id']}/export?format=obj", headers=auth)
        self.assertEqual(status, 200)
        self.assertGreater(raw.decode().count("\nf "), 100)
        # A strip has no crease pattern; a composite without a development neither.
        with open(DEMO) as f:
            strip = self.daemon.json("POST", "/api/sessions", json.load(f))[2]
        status, _, body = self.daemon.json("GET", f"/api/sessions/{strip['id']}/export?format=svg",
                                           headers={"Authorization": "Bearer " + strip["view_token"]})
        self.assertEqual((status, body["error"]["path"]), (400, "format"))
        self.assertIn("strip", body["error"]["message"])
        with open(os.path.join(ROOT, "examples", "composite-two-creases.json")) as f:
            scene = json.load(f)
        scene["model"].pop("development", None)  # a composite without a development
        plain = self.daemon.json("POST", "/api/sessions", scene)[2]
        status, _, body = self.daemon.json("GET", f"/api/sessions/{plain['id']}/export?format=fold",
                                           headers={"Authorization": "Bearer " + plain["view_token"]})
        self.assertEqual((status, body["error"]["path"]), (400, "format"))
        self.assertIn("development", body["error"]["message"])

    def test_exports_the_model_state_cannot_produce_are_422_naming_format_and_the_reason(self):
        # The development pinned to the mirror image of the sheet's corners: its faces turn
        # clockwise, which no crease pattern accepts (fold and svg), while the surface (obj) exports.
        with open(COMPOSITE) as f:
            scene = json.load(f)
        corners = [{"vertex": v, "at": [-scene["model"]["vertices"][v][0], scene["model"]["vertices"][v][1]]}
                   for v in (0, 2, 3, 5)]
        scene["model"]["development"] = {"samples": 4, "domain": {"corners": corners}}
        scene["solver"] = {"iterations": 2}
        status, _, s = self.daemon.json("POST", "/api/sessions", scene)
        self.assertEqual(status, 201, s)
        auth = {"Authorization": "Bearer " + s["view_token"]}
        for fmt in ("fold", "svg"):
            status, headers, body = self.daemon.json("GET", f"/api/sessions/{s['id']}/export?format={fmt}", headers=auth)
            self.assertEqual(status, 422, body)
            self.assertEqual((body["error"]["code"], body["error"]["path"]), ("unprocessable", "format"))
            self.assertTrue(body["error"]["message"].startswith(f"format: {fmt}:"), body["error"]["message"])
            self.assertIn("counter-clockwise", body["error"]["message"])
        self.assertEqual(self.daemon.request("GET", f"/api/sessions/{s['id']}/export?format=obj", headers=auth)[0], 200)
        # The same for a finished job's solved scene.
        job = self.daemon.json("POST", "/api/jobs", scene)[2]["id"]
        for _ in range(600):
            state = self.daemon.json("GET", "/api/jobs/" + job)[2]["state"]
            if state in ("succeeded", "failed"):
                break
            time.sleep(0.05)
        self.assertEqual(state, "succeeded")
        status, _, body = self.daemon.json("GET", f"/api/jobs/{job}/result?format=svg")
        self.assertEqual((status, body["error"]["path"]), (422, "format"), body)
        self.assertIn("svg", body["error"]["message"])

    def test_job_results_of_composites_export_fold(self):
        with open(COMPOSITE) as f:
            scene = json.load(f)
        job = self.daemon.json("POST", "/api/jobs", scene)[2]["id"]
        for _ in range(600):
            body = self.daemon.json("GET", "/api/jobs/" + job)[2]
            if body["state"] in ("succeeded", "failed"):
                break
            time.sleep(0.05)
        self.assertEqual(body["state"], "succeeded")
        status, _, raw = self.daemon.request("GET", f"/api/jobs/{job}/result?format=fold")
        self.assertEqual(status, 200)
        self.assertEqual(json.loads(raw)["file_spec"], 1.2)
        status, _, raw = self.daemon.request("GET", f"/api/jobs/{job}/result?format=svg")
        self.assertEqual(status, 200)
        self.assertIn(b"<svg", raw)
        fold = json.loads(self.daemon.request("GET", f"/api/jobs/{job}/result?format=fold")[2])
        self.assertTrue({"M", "V"} & set(fold["edges_assignment"]), "the lifted corner folds the crease")


if __name__ == "__main__":
    unittest.main()
