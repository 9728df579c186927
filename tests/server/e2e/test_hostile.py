"""Issue 12: hostile input and access control, sent by an independent client."""
import asyncio
import json
import os
import random
import shutil
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
