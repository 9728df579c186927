"""Restarts: no acknowledged edit lost, and the state restored exactly."""
import asyncio
import json
import os
import random
import shutil
import signal
import tempfile
import time
import unittest

import websockets

from daemon import (BIN, COMPOSITE, CONICAL, DEMO, QUASI, ROOT, Daemon, DaemonTestCase, drag, join,
                    numbers, open_store, recv_until, store_args)


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
            trials = 14
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


class ExactRestoreTest(unittest.TestCase):
    """Issue 12: after SIGKILL a restart restores the state clients read at the last acknowledged
    seq, not a re-solve of the journal (releases run under time budgets, so a replay differs)."""

    CASES = (("strip-lifted-corner.json", {"curve": "b", "index": 6}),
             ("composite-curved-fold.json", {"vertex": 3}),
             ("quasi-strip-twisted.json", {"curve": "c1", "index": 2}),
             ("conical-strip-hull.json", {"curve": "p", "index": 1}),
             ("spline-watertight.json", {"on": "control", "vertex": 60}))
    # Kill-and-restore rounds: the second restores a store that a restore wrote, the third adds
    # nothing new to that chain (CMake runs the PostgreSQL store with two, for CI time).
    ROUNDS = int(os.environ.get("DEVSURF_EXACT_ROUNDS", "3"))

    @staticmethod
    def point(model, target):
        if target.get("on") == "control":
            return model["control"]["points"][target["vertex"]]
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
            for round_ in range(self.ROUNDS):
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


def model_size(model):
    xs = numbers({k: v for k, v in model.items() if k not in ("handles",)})
    return max(xs) - min(xs)


def control_points(kind, model):
    """The scene's control points in the order an iterate's geometry carries them."""
    if kind == "strip":
        return model["a"]["points"] + model["b"]["points"]
    if kind == "composite":
        pts = list(model["vertices"])
        for e in model["edges"]:
            if e.get("type", "S") == "S" and "points" in e:
                pts += e["points"]  # a scene lists the interior control points only
        return pts
    if kind == "quasi_strip":
        return model["c1"]["points"] + model["c2"]["points"]
    return model["p"]["points"] + model["q"]["points"]


def iterate_points(kind, geometry):
    import base64
    import struct

    def rows(a):
        raw = base64.b64decode(a["data"])
        vals = struct.unpack("<%df" % (len(raw) // 4), raw)
        return [list(vals[i:i + 3]) for i in range(0, len(vals), 3)]
    if kind == "composite":
        return rows(geometry["points"]["positions"])
    names = {"strip": ("a", "b"), "quasi_strip": ("c1", "c2"), "conical_strip": ("p", "q")}[kind]
    return rows(geometry["control_points"][names[0]]) + rows(geometry["control_points"][names[1]])


class KillUnderAnEditStreamTest(unittest.TestCase):
    """Issue 12: SIGKILL at random moments while a client streams drags and structural edits, over
    strip, composite, quasi_strip and conical_strip sessions. A second reader (the store file,
    opened with Python's sqlite3 while the daemon is dead) checks the chain: every state a
    client was shown is durable (its revision is at most the stored one, and a stored revision a
    client saw holds the numbers it saw), every acknowledged seq is stored, and the restart
    restores the stored state bit for bit (when no acknowledged edit came after it)."""

    TRIALS = int(os.environ.get("DEVSURF_KILL_TRIALS", "18"))  # 28 until stop 52 (CI time)
    KINDS = (
        ("strip", "strip-lifted-corner.json",
         [{"curve": "b", "index": 6}, {"curve": "a", "index": 6}, {"curve": "b", "index": 3}]),
        ("composite", "composite-curved-fold.json",
         [{"vertex": 3}, {"vertex": 2}, {"edge": 3, "index": 1}]),
        ("quasi_strip", "quasi-strip-twisted.json",
         [{"curve": "c1", "index": 2}, {"curve": "c2", "index": 3}]),
        ("conical_strip", "conical-strip-hull.json",
         [{"curve": "p", "index": 1}, {"curve": "q", "index": 5}]),
    )

    @staticmethod
    def point_of(model, target):
        if "vertex" in target:
            return model["vertices"][target["vertex"]]
        if "edge" in target:
            return model["edges"][target["edge"]]["points"][target["index"]]
        return model[target["curve"]]["points"][target["index"]]

    def structural_edit(self, kind, rng, op, model):
        choice = rng.random()
        if choice < 0.25:
            return {"type": rng.choice(["undo", "redo"]), "op": op}
        if kind == "strip":
            if choice < 0.5:
                return {"type": "set_fixed", "op": op, "target": {"curve": "a", "index": 3}, "fixed": rng.random() < 0.5}
            if choice < 0.75:
                p = self.point_of(model, {"curve": "a", "index": 5})
                return {"type": "add_handle", "op": op, "target": {"curve": "a", "index": 5},
                        "position": [p[0], p[1], p[2] + rng.uniform(-0.2, 0.2)]}
            return {"type": "solve", "op": op}
        if kind == "composite":
            if choice < 0.5:
                return {"type": "set_crease", "op": op, "edge": 0, "crease": rng.choice(["fold", "none", "smooth"])}
            if choice < 0.75:
                return {"type": "set_fixed", "op": op, "target": {"vertex": 2}, "fixed": rng.random() < 0.5}
            return {"type": "solve", "op": op}
        if kind == "quasi_strip":
            return {"type": "set_params", "op": op, "params": {"samples": rng.randint(60, 120)}}
        return {"type": "set_params", "op": op, "params": {"np": rng.randint(30, 50)}}

    def read_store(self, data_dir, session):
        con = open_store(data_dir)
        try:
            last_seq = con.execute("SELECT last_seq FROM sessions WHERE id = ?", (session,)).fetchone()[0]
            row = con.execute("SELECT seq, revision, scene FROM snapshots WHERE session_id = ? ORDER BY seq DESC LIMIT 1",
                              (session,)).fetchone()
            if row is None:  # nothing shown since the session was created: revision 0, the initial scene
                row = (0, 0) + con.execute("SELECT initial_scene FROM sessions WHERE id = ?", (session,)).fetchone()
            after = [json.loads(e)["type"] for (e,) in con.execute(
                "SELECT edit FROM edits WHERE session_id = ? AND seq > ? ORDER BY seq", (session, row[0]))]
        finally:
            con.close()
        return last_seq, (row[0], row[1], json.loads(row[2])), after

    def test_sigkill_under_drags_and_edits_loses_nothing_shown_and_restores_the_stored_state(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-killstream-")
        rng = random.Random(12)
        tally = {"trials": 0, "compared_exactly": 0, "compared_float32": 0, "unobserved_in_flight": 0,
                 "acked_after_last_shown": 0, "messages": 0}
        try:
            daemon = Daemon(tmp).start()
            sessions = []
            for kind, name, targets in self.KINDS:
                with open(os.path.join(ROOT, "examples", name)) as f:
                    status, _, body = daemon.json("POST", "/api/sessions", json.load(f))
                self.assertEqual(status, 201, body)
                sessions.append((kind, targets, body))
            op = 0
            for trial in range(self.TRIALS):
                kind, targets, s = sessions[trial % len(sessions)]
                auth = {"Authorization": "Bearer " + s["view_token"]}
                # The daemon of the last trial's restore check goes on serving this one (a start
                # restores from the store either way; one start a trial, not two).
                observed = {}   # revision → ("exact", model) or ("float32", points)
                acked = [0]

                async def stream():
                    nonlocal op
                    ws, state = await join(daemon.port, s["id"], s["edit_token"])
                    model = state["scene"]["model"]
                    size = model_size(model)
                    observed[state["revision"]] = ("exact", model)

                    async def reader():
                        try:
                            async for raw in ws:
                                m = json.loads(raw)
                                tally["messages"] += 1
                                if m["type"] == "ack":
                                    acked[0] = max(acked[0], m["seq"])
                                elif m["type"] == "update":
                                    observed[m["revision"]] = ("exact", m["scene"]["model"])
                                elif m["type"] == "iterate":
                                    observed.setdefault(m["revision"], ("float32", iterate_points(kind, m["geometry"])))
                                elif m["type"] in ("solved", "error") and "revision" in m:
                                    observed.setdefault(m["revision"], ("seen", None))
                        except Exception:
                            pass

                    async def poller():
                        # A second reader over REST: the last state shown, in doubles.
                        loop = asyncio.get_running_loop()
                        while True:
                            try:
                                status, _, body = await loop.run_in_executor(
                                    None, lambda: daemon.json("GET", f"/api/sessions/{s['id']}", headers=auth))
                            except Exception:
                                return
                            if status == 200:
                                observed[body["revision"]] = ("exact", body["scene"]["model"])
                            await asyncio.sleep(0.02)

                    reading = asyncio.ensure_future(reader())
                    polling = asyncio.ensure_future(poller())
                    kill_at = time.monotonic() + rng.uniform(0.15, 1.2)
                    dragging = None
                    while time.monotonic() < kill_at:
                        op += 1
                        if dragging is None and rng.random() < 0.2:
                            await ws.send(json.dumps(self.structural_edit(kind, rng, op, model)))
                            await asyncio.sleep(rng.uniform(0.0, 0.05))
                            continue
                        if dragging is None:
                            dragging = rng.choice(targets)
                            start = self.point_of(model, dragging)
                            direction = [rng.uniform(-1, 1) for _ in range(3)]
                            step = 0
                        step += 1
                        position = [start[i] + 0.004 * size * step * direction[i] for i in range(3)]
                        await ws.send(json.dumps({"type": "drag", "op": op, "target": dragging, "position": position}))
                        if step >= rng.randint(3, 15):
                            op += 1
                            await ws.send(json.dumps({"type": "drag_end", "op": op, "target": dragging}))
                            dragging = None
                        await asyncio.sleep(rng.uniform(0.005, 0.03))
                    daemon.kill()
                    await asyncio.sleep(0.05)
                    reading.cancel()
                    polling.cancel()
                    try:
                        await ws.close()
                    except Exception:
                        pass
                    return size

                size = asyncio.run(stream())
                tally["trials"] += 1
                last_seq, stored, edits_after = self.read_store(tmp, s["id"])
                stored_seq, stored_revision, stored_scene = stored
                self.assertGreaterEqual(last_seq, acked[0], f"trial {trial} ({kind}): an acknowledged edit is not in the journal")
                shown = max(observed)
                self.assertGreaterEqual(stored_revision, shown,
                                        f"trial {trial} ({kind}): revision {shown} was shown but only {stored_revision} is stored")
                if stored_revision in observed and observed[stored_revision][0] == "exact":
                    before, after = numbers(observed[stored_revision][1]), numbers(stored_scene["model"])
                    self.assertEqual(before, after, f"trial {trial} ({kind}): the stored state differs from the one shown")
                    tally["compared_exactly"] += 1
                elif stored_revision in observed and observed[stored_revision][0] == "float32":
                    seen_points = observed[stored_revision][1]
                    stored_points = control_points(kind, stored_scene["model"])
                    self.assertEqual(len(seen_points), len(stored_points))
                    worst = max(abs(a - b) for p, q in zip(seen_points, stored_points) for a, b in zip(p, q))
                    self.assertLessEqual(worst, 1e-6 * max(1.0, size), f"trial {trial} ({kind}): stored state differs from the iterate shown")
                    tally["compared_float32"] += 1
                elif stored_revision not in observed:
                    tally["unobserved_in_flight"] += 1
                # The restart restores exactly the stored state, with every acknowledged seq.
                daemon = Daemon(tmp).start()
                status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}", headers=auth)
                self.assertEqual(status, 200, f"trial {trial} ({kind}): {body}")
                self.assertEqual(body["seq"], last_seq, f"trial {trial} ({kind})")
                if stored_seq == last_seq:
                    self.assertEqual(body["revision"], stored_revision)
                    self.assertEqual(numbers(body["scene"]["model"]), numbers(stored_scene["model"]),
                                     f"trial {trial} ({kind}): restored state differs from the stored one")
                else:
                    tally["acked_after_last_shown"] += 1
                    self.assertEqual(body["revision"], stored_revision + 1)
                    self.assertEqual(len(edits_after), last_seq - stored_seq, "the journal has every edit after the checkpoint")
                    if kind in ("strip", "composite") and set(edits_after) <= {"drag", "drag_end", "solve"}:
                        # Applied without their solves, these move no control point (a drag of a point
                        # with a handle moves the handle's target; a rebuild maps the numbers through the
                        # model's normalization: equal within 1e-12 of the size).
                        worst = max(abs(a - b) for a, b in zip(numbers(control_points(kind, body["scene"]["model"])),
                                                               numbers(control_points(kind, stored_scene["model"]))))
                        self.assertLessEqual(worst, 1e-12 * size,
                                             f"trial {trial} ({kind}): edits {edits_after} after the checkpoint changed the scene")
                        tally["acked_after_compared_exactly"] = tally.get("acked_after_compared_exactly", 0) + 1
                self.assertNotIn("null", json.dumps(body["scene"]))
            daemon.kill()
            print("\nkill trials:", json.dumps(tally))
            self.assertGreater(tally["compared_exactly"] + tally["compared_float32"], self.TRIALS // 2)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


class JobRestartTest(unittest.TestCase):
    """Issue 12: a job interrupted by SIGKILL is run again after the restart and gives the same
    result as the same job run without interruption (solves are deterministic: no time budget)."""

    def test_a_job_killed_while_running_finishes_after_the_restart_with_the_same_result(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-jobkill-")
        try:
            with open(COMPOSITE) as f:
                scene = json.load(f)
            # Long enough to be killed while running: every iteration runs (no early stop).
            scene["solver"] = dict(scene.get("solver", {}), iterations=3000, residual_tolerance=0,
                                   relative_change_tolerance=0)
            daemon = Daemon(tmp).start()
            status, _, body = daemon.json("POST", "/api/jobs", scene)
            self.assertEqual(status, 202, body)
            killed_job = body["id"]
            deadline = time.monotonic() + 60
            while True:
                status, _, job = daemon.json("GET", f"/api/jobs/{killed_job}")
                if job["state"] == "running" and job["progress"]["iteration"] > 10:
                    break
                self.assertLess(time.monotonic(), deadline, job)
                time.sleep(0.02)
            self.assertLess(job["progress"]["iteration"], 3000, "the job finished before it could be killed")
            daemon.kill()
            daemon = Daemon(tmp).start()
            status, _, body = daemon.json("POST", "/api/jobs", scene)  # the same scene, uninterrupted
            self.assertEqual(status, 202, body)
            fresh_job = body["id"]
            reports = {}
            for job_id in (killed_job, fresh_job):
                deadline = time.monotonic() + 300
                while True:
                    status, _, job = daemon.json("GET", f"/api/jobs/{job_id}")
                    if job["state"] not in ("queued", "running"):
                        break
                    self.assertLess(time.monotonic(), deadline, job)
                    time.sleep(0.1)
                self.assertEqual(job["state"], "succeeded", job)
                reports[job_id] = job["report"]
            a, b = reports[killed_job], reports[fresh_job]
            self.assertEqual(a["iterations"], b["iterations"])
            self.assertEqual(numbers(a["scene"]["model"]), numbers(b["scene"]["model"]))
            self.assertEqual(a["metrics"], b["metrics"])
            daemon.stop()
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


class QuarantineTest(unittest.TestCase):
    """Issue 12: a session that cannot be restored is kept, quarantined and reported — never
    deleted — and every other session is restored as usual."""

    def test_unrestorable_sessions_are_quarantined_kept_and_reported(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-quarantine-")
        try:
            daemon = Daemon(tmp).start()
            created = []
            for _ in range(4):
                with open(DEMO) as f:
                    status, _, body = daemon.json("POST", "/api/sessions", json.load(f))
                self.assertEqual(status, 201, body)
                created.append(body)

            async def edit(s):
                ws, state = await join(daemon.port, s["id"], s["edit_token"])
                await ws.send(drag(1, 0.6))
                await ws.send(json.dumps({"type": "drag_end", "op": 2, "target": {"curve": "b", "index": 6}}))
                await recv_until(ws, lambda m: m["type"] == "solved", timeout=30)
                await ws.close()
            for s in created:
                asyncio.run(edit(s))
            daemon.kill()
            con = open_store(tmp)
            unreadable, invalid, healthy, broken_initial = created
            con.execute("UPDATE sessions SET initial_scene = 'not json' WHERE id = ?", (broken_initial["id"],))
            con.execute("DELETE FROM snapshots WHERE session_id = ?", (broken_initial["id"],))
            con.execute("UPDATE snapshots SET scene = '{\"format\": tru' WHERE session_id = ?", (unreadable["id"],))
            bad_scene = json.loads(con.execute("SELECT scene FROM snapshots WHERE session_id = ? ORDER BY seq DESC",
                                               (invalid["id"],)).fetchone()[0])
            bad_scene_fixed = json.loads(json.dumps(bad_scene))
            bad_scene["model"]["fixed"] = [{"curve": "a", "index": 99}]
            con.execute("UPDATE snapshots SET scene = ? WHERE session_id = ?", (json.dumps(bad_scene), invalid["id"]))
            rows_before = {s["id"]: con.execute("SELECT COUNT(*) FROM snapshots WHERE session_id = ?", (s["id"],)).fetchone()[0]
                           + con.execute("SELECT COUNT(*) FROM edits WHERE session_id = ?", (s["id"],)).fetchone()[0]
                           for s in created}
            con.commit()
            con.close()
            for round_ in range(2):  # quarantined again after another restart: nothing was deleted
                daemon = Daemon(tmp).start()
                status, _, health = daemon.json("GET", "/api/health")
                self.assertEqual(health["sessions_quarantined"], 3, health)
                status, _, body = daemon.json("GET", f"/api/sessions/{broken_initial['id']}",
                                              headers={"Authorization": "Bearer " + broken_initial["view_token"]})
                self.assertEqual((status, body["error"]["code"]), (503, "quarantined"), body)
                for s in (unreadable, invalid):
                    auth = {"Authorization": "Bearer " + s["view_token"]}
                    status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}", headers=auth)
                    self.assertEqual(status, 503, body)
                    self.assertEqual(body["error"]["code"], "quarantined")
                    status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}", headers={"Authorization": "Bearer x"})
                    self.assertEqual(status, 404, "a wrong token learns nothing")
                    status, _, scene = daemon.json("GET", f"/api/sessions/{s['id']}/export?format=json", headers=auth)
                    self.assertEqual(status, 200, scene)
                    self.assertEqual(scene["format"], "devsurf-scene")
                async def join_quarantined():
                    ws = await websockets.connect(f"ws://127.0.0.1:{daemon.port}/ws")
                    await ws.send(json.dumps({"type": "join", "session": invalid["id"], "token": invalid["edit_token"]}))
                    answer = json.loads(await asyncio.wait_for(ws.recv(), 10))
                    await ws.close()
                    return answer
                answer = asyncio.run(join_quarantined())
                self.assertEqual((answer["type"], answer["code"], answer["path"]), ("error", "quarantined", "session"), answer)
                status, _, scene = daemon.json("GET", f"/api/sessions/{invalid['id']}/export?format=json",
                                               headers={"Authorization": "Bearer " + invalid["edit_token"]})
                self.assertEqual(scene["model"]["fixed"], [{"curve": "a", "index": 99}], "the stored design comes back as stored")
                status, _, body = daemon.json("GET", f"/api/sessions/{healthy['id']}",
                                              headers={"Authorization": "Bearer " + healthy["view_token"]})
                self.assertEqual(status, 200, body)
                daemon.stop()
            con = open_store(tmp)
            reasons = dict(con.execute("SELECT id, quarantine FROM sessions"))
            for s in created:
                rows = (con.execute("SELECT COUNT(*) FROM snapshots WHERE session_id = ?", (s["id"],)).fetchone()[0]
                        + con.execute("SELECT COUNT(*) FROM edits WHERE session_id = ?", (s["id"],)).fetchone()[0])
                self.assertEqual(rows, rows_before[s["id"]], "no row of any session was deleted")
            con.close()
            self.assertIn("snapshot", reasons[unreadable["id"]])
            self.assertIn("model.fixed[0]", reasons[invalid["id"]])
            self.assertIn("initial scene", reasons[broken_initial["id"]])
            self.assertIsNone(reasons[healthy["id"]])
            # Repaired by an operator, a quarantined session comes back at the next start; its owner
            # may delete one that stays broken (the daemon never does).
            con = open_store(tmp)
            con.execute("UPDATE snapshots SET scene = ? WHERE session_id = ?", (json.dumps(bad_scene_fixed), invalid["id"]))
            con.commit()
            con.close()
            daemon = Daemon(tmp).start()
            status, _, health = daemon.json("GET", "/api/health")
            self.assertEqual(health["sessions_quarantined"], 2, health)
            status, _, body = daemon.json("GET", f"/api/sessions/{invalid['id']}",
                                          headers={"Authorization": "Bearer " + invalid["view_token"]})
            self.assertEqual(status, 200, body)
            status, _, _ = daemon.json("DELETE", f"/api/sessions/{unreadable['id']}",
                                       headers={"Authorization": "Bearer " + unreadable["view_token"]})
            self.assertEqual(status, 403)
            status, _, _ = daemon.json("DELETE", f"/api/sessions/{unreadable['id']}",
                                       headers={"Authorization": "Bearer " + unreadable["edit_token"]})
            self.assertEqual(status, 204)
            status, _, health = daemon.json("GET", "/api/health")
            self.assertEqual(health["sessions_quarantined"], 1, health)
            daemon.stop()
            con = open_store(tmp)
            reasons = dict(con.execute("SELECT id, quarantine FROM sessions"))
            con.close()
            self.assertIsNone(reasons[invalid["id"]], "the quarantine is lifted once the session restores")
            self.assertNotIn(unreadable["id"], reasons)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


class SignalDuringStartUpTest(unittest.TestCase):
    """Issue 12: a SIGTERM while a restarted daemon restores its sessions ends the start-up there
    (exit 0, nothing served) instead of being ignored until every session is back."""

    def test_sigterm_while_restoring_stops_the_daemon_and_loses_nothing(self):
        import subprocess
        tmp = tempfile.mkdtemp(prefix="devsurf-startsig-")
        try:
            daemon = Daemon(tmp, "--session-time-budget-ms", "120000").start()
            with open(CONICAL) as f:
                scene = json.load(f)
            scene["model"]["np"] = scene["model"]["nq"] = 1500  # each one takes a second or more to solve
            ids = []
            for _ in range(3):
                status, _, body = daemon.json("POST", "/api/sessions", scene)
                self.assertEqual(status, 201, body)
                ids.append(body)
            daemon.stop()
            log_path = os.path.join(tmp, "start.log")
            with open(log_path, "w") as log:
                proc = subprocess.Popen([BIN, "serve", "--port", "0", "--data", tmp, *store_args(tmp),
                                         "--log-level", "info"],
                                        stdout=subprocess.PIPE, stderr=log, text=True)
                # Signalled once it is restoring (three whole conical solves): under load the
                # process may take longer than any fixed sleep just to load its libraries.
                deadline = time.monotonic() + 60
                while time.monotonic() < deadline:
                    with open(log_path) as f:
                        if "stored session(s)" in f.read():
                            break
                    time.sleep(0.02)
                else:
                    proc.kill()
                    with open(log_path) as f:
                        self.fail("the daemon never said it was restoring: " + f.read()[-2000:])
                time.sleep(0.2)
                proc.send_signal(signal.SIGTERM)
                out, _ = proc.communicate(timeout=120)
            self.assertEqual(proc.returncode, 0)
            self.assertNotIn("serving on", out, "it must not start serving after the signal")
            with open(log_path) as f:
                self.assertIn("stopped during start-up", f.read())
            con = open_store(tmp)  # and everything is still stored, nothing quarantined
            rows = dict(con.execute("SELECT id, quarantine FROM sessions"))
            con.close()
            for s in ids:
                self.assertIn(s["id"], rows)
                self.assertIsNone(rows[s["id"]])
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
