"""Composite sessions: geometry, drags, creases, exports."""
import asyncio
import json
import os
import random
import shutil
import subprocess
import tempfile
import time
import unittest

import websockets

from daemon import (BIN, COMPOSITE, CONICAL, DEMO, QUASI, ROOT, Daemon, DaemonTestCase, drag, join,
                    numbers, recv_until)


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

    def test_a_session_opened_solved_starts_where_the_scene_solves_to_and_a_bad_flag_is_400(self):
        with open(COMPOSITE) as f:
            scene = json.load(f)  # flat, its handle pulling vertex 3 up to z = 0.8
        states = {}
        for flag in ("", "?solved=false", "?solved=true"):
            status, _, body = self.daemon.json("POST", "/api/sessions" + flag, scene)
            self.assertEqual(status, 201, body)
            status, _, shown = self.daemon.json("GET", f"/api/sessions/{body['id']}",
                                                headers={"Authorization": "Bearer " + body["view_token"]})
            self.assertEqual(status, 200, shown)
            states[flag] = shown["scene"]["model"]["vertices"][3][2]
        self.assertEqual(states[""], 0.0)
        self.assertEqual(states["?solved=false"], 0.0)
        self.assertGreater(states["?solved=true"], 0.5, "the handle pulled the corner up before anyone joined")
        status, _, body = self.daemon.json("POST", "/api/sessions?solved=yes", scene)
        self.assertEqual((status, body["error"]["path"]), (400, "solved"), body)

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
        # A strip has no crease pattern (its svg is the strip unrolled); a composite without a
        # development neither.
        with open(DEMO) as f:
            strip = self.daemon.json("POST", "/api/sessions", json.load(f))[2]
        status, _, body = self.daemon.json("GET", f"/api/sessions/{strip['id']}/export?format=fold",
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
        for fmt in ("fold", "svg", "dxf"):
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


class ConcurrentJobsTest(DaemonTestCase):
    """Jobs solved at the same moment on two job workers give exactly what `devsurf solve` gives
    each scene alone, in a process of its own. Two scenes whose systems CHOLMOD factorizes (its
    nested-dissection ordering and the BLAS under it): with Debian's serial OpenBLAS (no locks)
    two factorizations at once corrupted each other, and METIS's one random generator made two
    orderings at once differ from the ordering made alone."""

    PREFIX = "devsurf-proto-jobs-"
    DAEMON_ARGS = ("--job-workers", "2")
    SCENES = ("composite-pleated-sheet.json", "quad-bend-sheet.json")

    def test_two_jobs_at_once_solve_to_the_models_the_cli_solves_alone(self):
        alone, jobs = {}, []
        for name in self.SCENES:
            path = os.path.join(ROOT, "examples", name)
            with tempfile.TemporaryDirectory() as tmp:
                out = os.path.join(tmp, "report.json")
                run = subprocess.run([BIN, "solve", path, "--out", out], capture_output=True, text=True, timeout=120)
                self.assertEqual(run.returncode, 0, run.stderr)
                with open(out) as f:
                    alone[name] = json.load(f)["scene"]["model"]
            with open(path) as f:
                scene = json.load(f)
            for _ in range(2):  # each scene twice: the four jobs run two at a time
                jobs.append((name, scene))
        ids = []
        for name, scene in jobs:
            status, _, body = self.daemon.json("POST", "/api/jobs", scene)
            self.assertEqual(status, 202, body)
            ids.append((name, body["id"]))
        for name, job in ids:
            for _ in range(1200):
                body = self.daemon.json("GET", "/api/jobs/" + job)[2]
                if body["state"] in ("succeeded", "failed", "cancelled"):
                    break
                time.sleep(0.05)
            self.assertEqual(body["state"], "succeeded", body)
            status, _, raw = self.daemon.request("GET", f"/api/jobs/{job}/result?format=json")
            self.assertEqual(status, 200)
            with self.subTest(scene=name, job=job):
                self.assertEqual(json.loads(raw)["scene"]["model"], alone[name], "bit for bit, as the JSON numbers")


if __name__ == "__main__":
    unittest.main()
