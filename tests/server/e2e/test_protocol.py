"""The WebSocket protocol and REST API of `devsurf serve` for strip sessions and jobs."""
import asyncio
import re
import subprocess
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
        status, _, raw = self.daemon.request("GET", f"/api/sessions/{s['id']}/export?format=step", headers=auth(s["view_token"]))
        self.assertEqual(status, 200)
        self.assertTrue(raw.startswith(b"ISO-10303-21;"))
        self.assertEqual(self.daemon.json("GET", f"/api/sessions/{s['id']}/export?format=dwg", headers=auth(s["view_token"]))[0], 400)
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

    def test_a_scene_posted_as_curl_d_posts_it_is_accepted_whatever_its_size(self):
        # curl -d labels the body application/x-www-form-urlencoded; the API reads JSON anyway.
        with open(os.path.join(ROOT, "examples", "composite-column.json"), "rb") as f:
            body = f.read()
        self.assertGreater(len(body), 8192)
        status, _, raw = self.daemon.request("POST", "/api/jobs", body,
                                             {"Content-Type": "application/x-www-form-urlencoded"})
        self.assertEqual(status, 202, raw[:300])

    def test_a_crease_pattern_uploaded_as_a_form_or_without_its_format_imports(self):
        # curl -F file=@pattern.svg, and a drawing posted as it is without ?format=svg: both were
        # refused as "not JSON (a FOLD file is JSON)" (stop 55's tryout).
        with open(os.path.join(ROOT, "tests", "data", "svg", "pleat.svg"), "rb") as f:
            drawing = f.read()
        status, _, doc = self.daemon.json("POST", "/api/imports", drawing, {"Content-Type": "image/svg+xml"})
        self.assertEqual(status, 200, doc)
        self.assertEqual(doc["summary"]["format"], "svg")
        self.assertEqual(doc["scene"]["model"]["kind"], "composite")

        def form(*files):
            boundary = "devsurf-e2e-boundary"
            body = b""
            for name, content in files:
                body += (f"--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{name}\"\r\n"
                         f"Content-Type: application/octet-stream\r\n\r\n").encode() + content + b"\r\n"
            body += f"--{boundary}--\r\n".encode()
            return body, {"Content-Type": f"multipart/form-data; boundary={boundary}"}

        body, headers = form(("pleat.svg", drawing))
        status, _, doc = self.daemon.json("POST", "/api/imports", body, headers)
        self.assertEqual(status, 200, doc)
        self.assertEqual(doc["summary"]["format"], "svg")
        with open(os.path.join(ROOT, "tests", "data", "fold", "simple.fold"), "rb") as f:
            body, headers = form(("simple.fold", f.read()))
        status, _, doc = self.daemon.json("POST", "/api/imports", body, headers)
        self.assertEqual(status, 200, doc)
        self.assertEqual(doc["summary"]["format"], "fold")
        body, headers = form(("a.svg", drawing), ("b.svg", drawing))
        status, _, doc = self.daemon.json("POST", "/api/imports", body, headers)
        self.assertEqual(status, 400, doc)
        self.assertEqual(doc["error"]["path"], "body")
        self.assertIn("one file", doc["error"]["message"])

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

    def finished_job(self, scene):
        """Submits the scene as a job and waits (30 s at most) until it has succeeded: its last state."""
        status, _, job = self.daemon.json("POST", "/api/jobs", scene)
        self.assertEqual(status, 202, job)
        for _ in range(600):
            status, _, state = self.daemon.json("GET", "/api/jobs/" + job["id"])
            if state["state"] in ("succeeded", "failed"):
                break
            time.sleep(0.05)
        self.assertEqual(state["state"], "succeeded", state)
        return state

    def test_an_uploaded_mesh_becomes_glued_patches_that_solve_as_a_job_and_open_as_a_session(self):
        # A gently curved 12 × 12 sheet as OFF text, approximated in 3 patches (issue 15).
        import math
        n = 12
        lines = ["OFF", f"{(n + 1) ** 2} {2 * n * n} 0"]
        lines += [f"{i / n} {j / n} {0.25 * math.sin(2 * i / n) * math.cos(j / n)}" for j in range(n + 1) for i in range(n + 1)]
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i
                lines += [f"3 {a} {a + 1} {a + n + 2}", f"3 {a} {a + n + 2} {a + n + 1}"]
        off = ("\n".join(lines) + "\n").encode()
        status, _, body = self.daemon.json("POST", "/api/approximations?format=off&segments=3&faces=300&iterations=20", off,
                                           {"Content-Type": "application/octet-stream"})
        self.assertEqual(status, 200, body)
        scene, summary = body["scene"], body["summary"]
        self.assertEqual(scene["model"]["kind"], "quad_mesh")
        self.assertEqual(scene["solver"]["iterations"], 20)
        self.assertGreater(summary["quads"], 200)
        self.assertGreaterEqual(summary["patches"], 2)
        self.assertEqual(len(scene["model"]["reference"]["faces"]), 2 * n * n)
        # As a batch job, with progress, to a developable result near the mesh.
        state = self.finished_job(scene)
        self.assertEqual(state["progress"]["iteration"], state["progress"]["of"])
        metrics = state["report"]["metrics"]
        self.assertLess(metrics["length_error"], 1e-3)
        self.assertLess(metrics["approximation_distance_rms_relative"], 0.01)
        # As a session.
        status, _, session = self.daemon.json("POST", "/api/sessions", scene)
        self.assertEqual(status, 201, session)
        # Bad input names the field and loses nothing.
        cases = [("format=dxf", off, "format"), ("format=off&segments=0", off, "segments"),
                 ("format=off&faces=lots", off, "faces"), ("format=off&colour=red", off, "colour"),
                 ("format=off&spacing=-1", off, "spacing"), ("format=off&units=furlong", off, "units"),
                 ("format=off", b"", "body"), ("format=off", b"OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "mesh"),
                 ("format=off", b"OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n", "mesh"),
                 ("format=off", b"OFF\nnot a mesh\n", "body")]
        for query, data, field in cases:
            status, _, err = self.daemon.json("POST", "/api/approximations?" + query, data,
                                              {"Content-Type": "application/octet-stream"})
            self.assertEqual(status, 400, (query, err))
            self.assertEqual(err["error"]["path"], field, (query, err))
        self.assertEqual(self.daemon.json("GET", "/api/health")[0], 200)

    def test_an_uploaded_cloud_is_previewed_fitted_by_a_strip_and_covered_by_strips(self):
        # A cylinder patch (radius 1, 100°, height 1.2) as XYZ text without normals (issue 15).
        import math
        import random
        rng = random.Random(7)
        rows = []
        for _ in range(3000):
            a = math.radians(-50 + 100 * rng.random())
            rows.append(f"{math.cos(a)} {math.sin(a)} {1.2 * rng.random()}")
        xyz = ("\n".join(rows) + "\n").encode()
        octet = {"Content-Type": "application/octet-stream"}
        status, _, preview = self.daemon.json("POST", "/api/references?format=xyz&points=500", xyz, octet)
        self.assertEqual(status, 200, preview)
        self.assertEqual((preview["points"], preview["shown"], len(preview["positions"])), (3000, 500, 1500))
        self.assertAlmostEqual(preview["diagonal"], math.dist(*preview["bounding_box"]), places=9)
        # A brush stroke → a strip that fits as a job.
        status, _, fit = self.daemon.json("POST", "/api/fits?format=xyz&centre=1,0,0.6&radius=0.6", xyz, octet)
        self.assertEqual(status, 200, fit)
        self.assertEqual(fit["scene"]["model"]["kind"], "strip")
        self.assertGreater(len(fit["scene"]["model"]["approximation"]["points"]), 30)
        # Strips side by side → a composite that solves as a job near the points.
        status, _, cover = self.daemon.json("POST", "/api/covers?format=xyz&strips=3", xyz, octet)
        self.assertEqual(status, 200, cover)
        self.assertEqual(cover["scene"]["model"]["kind"], "composite")
        self.assertEqual(len(cover["scene"]["model"]["faces"]), 3)
        self.assertEqual(len(cover["summary"]["pairings"]), 2)
        self.assertEqual(cover["summary"]["warnings"], [])
        self.assertLess(cover["summary"]["rounds"][-1]["gap_max"], 1e-3)
        for scene, metric in ((fit["scene"], "approximation_distance_rms_relative"), (cover["scene"], "warp_angle_max_deg")):
            state = self.finished_job(scene)
            self.assertLess(state["report"]["metrics"]["warp_angle_max_deg"], 0.05)
            self.assertLess(state["report"]["metrics"].get(metric, 0.0), 0.01)
        status, _, session = self.daemon.json("POST", "/api/sessions", fit["scene"])
        self.assertEqual(status, 201, session)
        # Fig. 10e: a closed can (its side and two discs, 4000 points) covered region by region.
        rows = []
        for _ in range(4000):
            a, pick = 2 * math.pi * rng.random(), rng.random() * (4 * math.pi + 2 * math.pi)
            if pick < 4 * math.pi:
                rows.append(f"{math.cos(a)} {math.sin(a)} {2 * rng.random() - 1}")
            else:
                r = math.sqrt(rng.random())
                rows.append(f"{r * math.cos(a)} {r * math.sin(a)} {1 if pick > 5 * math.pi else -1}")
        can = ("\n".join(rows) + "\n").encode()
        status, _, whole = self.daemon.json("POST", "/api/covers?format=xyz&regions=6&strips=3", can, octet)
        self.assertEqual(status, 200, whole)
        summary = whole["summary"]
        self.assertEqual(len(summary["regions"]), 6, summary)
        self.assertGreaterEqual(summary["covered_regions"], 5, summary)
        self.assertLessEqual(summary["warp_angle_max_deg"], 0.05)
        self.assertEqual(len(whole["scene"]["model"]["faces"]), 3 * summary["covered_regions"])
        state = self.finished_job(whole["scene"])
        self.assertLess(state["report"]["metrics"]["warp_angle_max_deg"], 0.05)
        # Bad input names the field.
        cases = [("/api/fits?format=dxf", xyz, "format"), ("/api/fits?format=xyz&centre=1,0", xyz, "centre"),
                 ("/api/fits?format=xyz&centre=1,0,0", xyz, "radius"), ("/api/fits?format=xyz&radius=-1&centre=0,0,0", xyz, "radius"),
                 ("/api/fits?format=xyz&centre=9,9,9&radius=0.1", xyz, "radius"), ("/api/fits?format=xyz&strips=3", xyz, "strips"),
                 ("/api/covers?format=xyz&strips=0", xyz, "strips"), ("/api/covers?format=xyz&crease=valley", xyz, "crease"),
                 ("/api/covers?format=xyz&centre=nan,0,0&radius=1", xyz, "centre"), ("/api/covers?format=xyz", b"", "body"),
                 ("/api/covers?format=xyz", b"1 2\n", "body"), ("/api/references?format=xyz&points=0", xyz, "points"),
                 ("/api/references?format=xyz&colour=red", xyz, "colour"), ("/api/covers?format=xyz&regions=0", xyz, "regions"),
                 ("/api/covers?format=xyz&regions=32&strips=8", xyz, "regions"), ("/api/fits?format=xyz&overhang=-1", xyz, "overhang"),
                 ("/api/fits?format=xyz&regions=2", xyz, "regions")]
        for route, data, field in cases:
            status, _, err = self.daemon.json("POST", route, data, octet)
            self.assertEqual(status, 400, (route, err))
            self.assertEqual(err["error"]["path"], field, (route, err))
        self.assertEqual(self.daemon.json("GET", "/api/health")[0], 200)

    def test_openapi_lists_every_route_and_metrics_are_prometheus_text(self):
        status, _, doc = self.daemon.json("GET", "/api/openapi.json")
        self.assertEqual(status, 200)
        self.assertEqual(doc["openapi"], "3.1.0")
        routes = {"/api/health", "/api/metrics", "/api/openapi.json", "/api/sessions", "/api/sessions/{id}", "/api/approximations",
                  "/api/references", "/api/fits", "/api/covers", "/api/imports",
                  "/api/sessions/{id}/export", "/api/sessions/{id}/thumbnail", "/api/jobs", "/api/jobs/{id}", "/api/jobs/{id}/cancel",
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
        # The address as `devsurf serve` prints it (a trailing slash), the scene on standard input.
        with open(os.path.join(ROOT, "examples", "strip-cone.json"), "rb") as scene:
            piped = subprocess.run([BIN, "job", "submit", "-", "--server", f"http://127.0.0.1:{self.daemon.port}/"],
                                   stdin=scene, capture_output=True, timeout=60)
        self.assertEqual(piped.returncode, 0, piped.stderr)
        self.assertTrue(json.loads(piped.stdout)["location"].startswith("/api/jobs/"))
        # Another scheme is refused by name (it aborted the CLI with an uncaught exception).
        ftp = subprocess.run([BIN, "job", "submit", DEMO, "--server", "ftp://x"], capture_output=True, text=True, timeout=60)
        self.assertEqual(ftp.returncode, 2, ftp.stderr)
        self.assertIn("--server", ftp.stderr)
        # --wait warns on a missed quality as `devsurf solve` does; --require-quality makes it exit 3.
        with open(os.path.join(ROOT, "examples", "strip-twisted.json")) as f:
            scene = json.load(f)
        scene.setdefault("solver", {})["iterations"] = 1
        with tempfile.TemporaryDirectory() as tmp:
            one = os.path.join(tmp, "one-iteration.json")
            with open(one, "w") as f:
                json.dump(scene, f)
            missed = subprocess.run([BIN, "job", "submit", one, "--server", f"http://127.0.0.1:{self.daemon.port}", "--wait",
                                     "--require-quality"], capture_output=True, text=True, timeout=120)
        self.assertEqual(missed.returncode, 3, missed.stderr)
        self.assertIn("misses its quality thresholds", missed.stderr)
