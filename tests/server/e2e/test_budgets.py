"""Issue 12, bounded resources: the runaway edits an outside tester sent (a quasi strip mapping
of degree 9 with 10 000 coefficients that grew the daemon to 8.8 GB, conical np = 100 000, quasi
samples = 100 000, a drag 10⁶ units away) are answered with clear errors naming the field, the
daemon's memory stays put, nothing is journalled (a restart is prompt), and jobs over their time
limit fail saying so."""
import asyncio
import json
import shutil
import tempfile
import time
import unittest

from daemon import CONICAL, QUASI, Daemon, DaemonTestCase, join, recv_until


def resident_mib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return 0.0


def create_session(daemon, path):
    with open(path) as f:
        scene = json.load(f)
    status, _, body = daemon.json("POST", "/api/sessions", scene)
    assert status == 201, (status, body)
    return body


async def answer(ws, op, timeout=60.0):
    """The ack or error of the message with this op (other messages skipped)."""
    seen = await recv_until(ws, lambda m: m.get("op") == op and m["type"] in ("ack", "error"), timeout)
    return seen[-1]


RUNAWAY_QUASI = {"type": "set_params", "op": "runaway", "params": {"mapping": {"degree": 9, "coefficients": 10000}}}
SAMPLES_QUASI = {"type": "set_params", "op": "samples", "params": {"samples": 100000}}
NP_CONICAL = {"type": "set_params", "op": "np", "params": {"np": 100000}}
SLOW_CONICAL = {"type": "set_params", "op": "slow", "params": {"np": 10000, "nq": 10000}}


class BudgetTest(DaemonTestCase):
    DAEMON_ARGS = ("--session-time-budget-ms", "3000", "--job-timeout-ms", "1500")
    PREFIX = "devsurf-budgets-"

    def test_the_runaway_edits_are_refused_naming_the_field_and_the_daemon_stays_small(self):
        quasi = create_session(self.daemon, QUASI)
        conical = create_session(self.daemon, CONICAL)
        demo = self.daemon.json("GET", "/api/sessions")[2]["sessions"][0]

        async def run():
            rss = resident_mib(self.daemon.proc.pid)
            ws, state = await join(self.daemon.port, quasi["id"], quasi["edit_token"])
            seq = state["seq"]
            await ws.send(json.dumps(RUNAWAY_QUASI))
            err = await answer(ws, "runaway")
            self.assertEqual(err["type"], "error")
            self.assertEqual(err["code"], "limit")
            self.assertEqual(err["path"], "params.mapping.coefficients")
            self.assertIn("over the budget of 512 MiB", err["message"])
            await ws.send(json.dumps(SAMPLES_QUASI))
            err = await answer(ws, "samples")
            self.assertEqual((err["code"], err["path"]), ("limit", "params.samples"))
            await ws.close()
            grown = resident_mib(self.daemon.proc.pid) - rss
            self.assertLess(grown, 200.0, f"the daemon grew by {grown:.0f} MiB")

            ws, _ = await join(self.daemon.port, conical["id"], conical["edit_token"])
            await ws.send(json.dumps(NP_CONICAL))
            err = await answer(ws, "np")
            self.assertEqual((err["code"], err["path"]), ("invalid", "params.np"))
            # Within the schema's maximum but tens of seconds of work: stopped by the time budget.
            await ws.send(json.dumps(SLOW_CONICAL))
            err = await answer(ws, "slow")
            self.assertEqual((err["code"], err["path"]), ("time_budget", "params"))
            self.assertIn("this session's time budget of 3000 ms was exceeded", err["message"])
            await ws.close()

            ws, _ = await join(self.daemon.port, demo["id"], demo["edit_token"])
            await ws.send(json.dumps({"type": "drag", "op": "far", "target": {"curve": "b", "index": 6},
                                      "position": [1e6, 0.0, 0.0]}))
            err = await answer(ws, "far")
            self.assertEqual((err["code"], err["path"]), ("invalid", "position"))
            await ws.close()
            return seq

        seq = asyncio.run(run())
        status, _, body = self.daemon.json("GET", f"/api/sessions/{quasi['id']}",
                                           headers={"Authorization": "Bearer " + quasi["view_token"]})
        self.assertEqual(status, 200)
        self.assertEqual(body["seq"], seq)  # nothing was journalled
        self.assertEqual(body["scene"]["model"]["mapping"]["coefficients"], 50)

    def test_a_scene_over_the_budget_is_a_400_limit_naming_the_field(self):
        with open(QUASI) as f:
            scene = json.load(f)
        scene["model"]["mapping"] = {"degree": 9, "coefficients": 10000}
        for route in ("/api/sessions", "/api/jobs"):
            status, _, body = self.daemon.json("POST", route, scene)
            self.assertEqual(status, 400, route)
            self.assertEqual(body["error"]["code"], "limit", route)
            self.assertEqual(body["error"]["path"], "model.mapping.coefficients", route)

    def test_a_job_of_any_kind_over_its_time_limit_fails_saying_so(self):
        with open(CONICAL) as f:
            conical = json.load(f)
        conical["model"]["np"] = conical["model"]["nq"] = 10000  # ~45 s of work
        with open(QUASI) as f:
            quasi = json.load(f)
        quasi["model"]["samples"] = 20000  # ~14 s of work
        for scene in (conical, quasi):
            status, _, body = self.daemon.json("POST", "/api/jobs", scene)
            self.assertEqual(status, 202, body)
            job = body["id"]
            deadline = time.monotonic() + 30.0  # far below the natural run of the conical job
            while True:
                body = self.daemon.json("GET", f"/api/jobs/{job}")[2]
                if body["state"] in ("succeeded", "failed", "cancelled") or time.monotonic() > deadline:
                    break
                time.sleep(0.1)
            self.assertEqual(body["state"], "failed", scene["model"]["kind"])
            self.assertEqual(body["error"], "the job's time limit of 1500 ms was exceeded "
                                            "(devsurf serve --job-timeout-ms); the job was stopped")


class BudgetRestartTest(unittest.TestCase):
    def test_after_the_runaway_edits_the_daemon_stops_and_restarts_promptly_with_the_same_state(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-budgets-restart-")
        try:
            daemon = Daemon(tmp, "--session-time-budget-ms", "3000").start()
            quasi = create_session(daemon, QUASI)
            conical = create_session(daemon, CONICAL)

            async def edits():
                ws, state = await join(daemon.port, quasi["id"], quasi["edit_token"])
                await ws.send(json.dumps(RUNAWAY_QUASI))
                self.assertEqual((await answer(ws, "runaway"))["code"], "limit")
                await ws.send(json.dumps({"type": "set_params", "op": "good", "params": {"samples": 120}}))
                self.assertEqual((await answer(ws, "good"))["type"], "ack")
                await ws.close()
                ws, _ = await join(daemon.port, conical["id"], conical["edit_token"])
                await ws.send(json.dumps(SLOW_CONICAL))
                self.assertEqual((await answer(ws, "slow"))["code"], "time_budget")
                await ws.close()

            asyncio.run(edits())
            before = {s["id"]: daemon.json("GET", f"/api/sessions/{s['id']}",
                                           headers={"Authorization": "Bearer " + s["view_token"]})[2]
                      for s in (quasi, conical)}
            self.assertEqual(daemon.stop(), 0)
            started = time.monotonic()
            daemon = Daemon(tmp, "--session-time-budget-ms", "3000").start()  # returns once it listens
            # Nothing runaway was journalled: the restart replays small edits only (a generous bound
            # for a loaded machine; the journalled runaway edit took 69 s before).
            self.assertLess(time.monotonic() - started, 30.0)
            for s in (quasi, conical):
                status, _, body = daemon.json("GET", f"/api/sessions/{s['id']}",
                                              headers={"Authorization": "Bearer " + s["view_token"]})
                self.assertEqual(status, 200)
                self.assertEqual(body["seq"], before[s["id"]]["seq"])
                self.assertEqual(body["scene"], before[s["id"]]["scene"])
            self.assertEqual(daemon.stop(), 0)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)



class DemoBudgetTest(unittest.TestCase):
    def test_demos_open_whatever_the_session_budget_which_still_bounds_what_users_send(self):
        tmp = tempfile.mkdtemp(prefix="devsurf-demo-budget-")
        # A conical strip of 200 × 200 samples takes ~1 s to build: ten times the budget.
        with open(CONICAL) as f:
            scene = json.load(f)
        scene["model"]["np"] = scene["model"]["nq"] = 200
        demo = f"{tmp}/conical-fine.json"
        with open(demo, "w") as f:
            json.dump(scene, f)
        daemon = Daemon(tmp + "/data", "--session-time-budget-ms", "100", "--demo", demo).start()
        try:
            deadline = time.monotonic() + 60
            ids = []
            while time.monotonic() < deadline:
                ids = [s["id"] for s in daemon.json("GET", "/api/sessions")[2]["sessions"]]
                if len(ids) == 2:
                    break
                time.sleep(0.2)
            self.assertIn("demo-conical-fine", ids, "the demo opens under a 100 ms budget")
            status, _, body = daemon.json("POST", "/api/sessions", scene)
            self.assertTrue(400 <= status < 500, (status, body))  # a user's scene is held to the budget
            self.assertEqual(body["error"]["code"], "time_budget")
        finally:
            daemon.stop()
            shutil.rmtree(tmp, ignore_errors=True)

if __name__ == "__main__":
    unittest.main()
