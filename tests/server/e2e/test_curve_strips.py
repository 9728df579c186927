"""Sessions of the strips between two curves (quasi_strip, conical_strip)."""
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
