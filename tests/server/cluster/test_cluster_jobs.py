"""Issue 18: batch jobs on the shared queue of three daemons behind HAProxy, one of them
SIGKILLed mid-run. Every job ends exactly once with its result, none is lost or duplicated;
progress, cancellation and idempotency keys hold across nodes. The store is read back with psql."""
import math
import os
import signal
import subprocess
import time
import unittest

from cluster_testing import example, http, psql, start_cluster, wait_for

JOBS = int(os.environ.get("DEVSURF_CLUSTER_JOBS", "200"))


def job_scene(iterations=60, points=100):
    """A strip of `points` control points per curve, solved for exactly `iterations` iterations
    (about 0.07 s at 60 and 100 points on this project's CI machine; the queue's semantics, not the
    solve, are under test: 200 points doubled the suite's CPU time spent solving)."""
    scene = example("strip-twisted.json")
    a, b = [], []
    for i in range(points):
        t = i / (points - 1)
        a.append([i * 0.05, 0.0, 0.0])
        b.append([i * 0.05, math.cos(t), math.sin(t)])
    scene["model"]["a"]["points"] = a
    scene["model"]["b"]["points"] = b
    scene["model"].pop("fixed", None)
    scene["solver"] = {"iterations": iterations, "residual_tolerance": 0, "relative_change_tolerance": 0}
    return scene


class JobsOnThreeDaemonsTest(unittest.TestCase):
    def test_every_job_finishes_exactly_once_when_a_daemon_is_killed_mid_run(self):
        cluster = start_cluster(self, nodes=3, lease_ms=2000, extra=["--max-jobs", "1000"])
        scene = job_scene()
        start = time.monotonic()
        ids = {}
        for k in range(JOBS):
            status, _, body = http(cluster.url("/api/jobs"), "POST", scene, {"Idempotency-Key": f"job-{k}"})
            self.assertEqual(status, 202, body)
            ids[k] = body["id"]
        self.assertEqual(len(set(ids.values())), JOBS)

        def succeeded():
            return int(psql(cluster.postgres, "SELECT count(*) FROM jobs WHERE state = 'succeeded'")[0][0])

        # Kill node2 while it runs a job, about a third of the way through. Seeing a job running
        # on node2 and killing it are two steps, and node2 may finish that job and be between
        # two claims by the time the kill lands (a busy CI run did: no job ran again). So
        # node2 is frozen (SIGSTOP) first, what it holds is read while it cannot change (after
        # 0.2 s for a commit already sent to reach the server), and it is killed only while it
        # holds a job; otherwise it is let go on and caught again.
        wait_for(lambda: succeeded() >= JOBS // 3, 300, what="a third of the jobs")
        node2 = cluster.node("node2")["pid"]

        def running_on_node2():
            return {r[0] for r in psql(cluster.postgres, "SELECT id FROM jobs WHERE state = 'running' "
                                                         "AND lease_owner = 'node2'") if r and r[0]}

        held = set()
        for _ in range(50):
            wait_for(running_on_node2, 30, step=0.01, what="a job running on node2")
            os.kill(node2, signal.SIGSTOP)
            time.sleep(0.2)
            held = running_on_node2()
            if held:
                break
            os.kill(node2, signal.SIGCONT)
        self.assertTrue(held, "node2 was caught holding a job")
        cluster.kill("node2")
        killed_at = time.monotonic()

        wait_for(lambda: succeeded() == JOBS, 600, step=0.25, what="every job to succeed")
        wall = time.monotonic() - start
        print(f"{JOBS} jobs on 3 daemons, node2 killed after {killed_at - start:.1f} s: all done in {wall:.1f} s")

        rows = psql(cluster.postgres, "SELECT id, state, attempt, report IS NOT NULL, lease_owner IS NULL, "
                                      "idempotency_key FROM jobs ORDER BY id")
        self.assertEqual(len(rows), JOBS, "no job lost, none duplicated")
        for job_id, state, attempt, has_report, lease_cleared, key in rows:
            self.assertEqual(state, "succeeded", job_id)
            self.assertEqual(has_report, "t", job_id)
            self.assertEqual(lease_cleared, "t", job_id)
            self.assertEqual(ids[int(key.split("-")[1])], job_id)
        rerun = {r[0] for r in rows if int(r[2]) > 1}
        self.assertEqual(rerun, held, "exactly the job node2 held when it was killed ran again elsewhere")
        self.assertEqual(len(held), 1, "node2 runs one job at a time (one worker)")

        # Each result is the solve of its scene: read back through HAProxy (any node).
        for k in range(0, JOBS, 37):
            status, _, report = http(cluster.url(f"/api/jobs/{ids[k]}/result"))
            self.assertEqual(status, 200, report)
            self.assertEqual(report["iterations"], 60)
            self.assertLess(report["metrics"]["warp_angle_max_deg"], 0.05)

        # Idempotency keys hold across nodes: the same key and body through HAProxy (round robin:
        # two other nodes) is the same job, a different body is refused.
        for k in (0, 1, 2):
            status, _, body = http(cluster.url("/api/jobs"), "POST", scene, {"Idempotency-Key": f"job-{k}"})
            self.assertEqual(status, 200, body)
            self.assertEqual(body["id"], ids[k])
        other = job_scene(iterations=61)
        status, _, body = http(cluster.url("/api/jobs"), "POST", other, {"Idempotency-Key": "job-0"})
        self.assertEqual(status, 422, body)
        self.assertEqual(body["error"]["code"], "idempotency_mismatch")

    def test_progress_and_cancellation_work_from_any_node(self):
        cluster = start_cluster(self, nodes=3, lease_ms=2000)
        slow = job_scene(iterations=5000, points=400)
        status, _, body = http(cluster.url("/api/jobs"), "POST", slow)
        self.assertEqual(status, 202, body)
        job_id = body["id"]
        runner = wait_for(lambda: (psql(cluster.postgres, f"SELECT lease_owner FROM jobs WHERE id = '{job_id}' "
                                                          "AND state = 'running'") or [[None]])[0][0],
                          60, what="the job to run")
        others = [n for n in cluster.nodes if n["id"] != runner]
        # Progress stored by the runner's heartbeat is seen on another node.
        def progress_elsewhere():
            _, _, j = http(f"http://127.0.0.1:{others[0]['port']}/api/jobs/{job_id}")
            return j["progress"]["iteration"] > 0 and j
        seen = wait_for(progress_elsewhere, 30, what="progress on another node")
        self.assertEqual(seen["state"], "running")
        # Cancelled through a node that does not run it.
        status, _, body = http(f"http://127.0.0.1:{others[1]['port']}/api/jobs/{job_id}/cancel", "POST")
        self.assertEqual(status, 202, body)
        wait_for(lambda: http(cluster.url(f"/api/jobs/{job_id}"))[2]["state"] == "cancelled", 30,
                 what="the cancellation")
        self.assertEqual(psql(cluster.postgres, f"SELECT lease_owner IS NULL FROM jobs WHERE id = '{job_id}'")[0][0], "t")


    def test_a_worker_process_claims_jobs_and_hands_them_back_when_stopped(self):
        cluster = start_cluster(self, nodes=1, lease_ms=2000, extra=["--max-jobs", "100"])
        log = open(os.path.join(cluster.dir, "worker.log"), "w")
        self.addCleanup(log.close)
        worker = subprocess.Popen([os.environ.get("DEVSURF_BIN", "devsurf"), "worker", "--store", cluster.postgres,
                                   "--node-id", "w1", "--lease-ms", "2000"], stdout=subprocess.PIPE, stderr=log, text=True)
        self.addCleanup(lambda: worker.poll() is None and worker.kill())
        self.assertIn("devsurf worker w1 claiming jobs", worker.stdout.readline())
        scene = job_scene(iterations=400, points=200)
        ids = [http(cluster.url("/api/jobs"), "POST", scene)[2]["id"] for _ in range(6)]
        running_on_worker = wait_for(lambda: psql(cluster.postgres, "SELECT id FROM jobs WHERE state = 'running' "
                                                                    "AND lease_owner = 'w1'"), 60,
                                     step=0.02, what="a job claimed by the worker")
        job_id = running_on_worker[0][0]
        worker.send_signal(signal.SIGTERM)
        self.assertEqual(worker.wait(timeout=30), 0)
        state, owner = psql(cluster.postgres, f"SELECT state, coalesce(lease_owner, '') FROM jobs WHERE id = '{job_id}'")[0]
        self.assertNotEqual(owner, "w1", "handed back: no longer the worker's")
        self.assertIn(state, ("queued", "running", "succeeded"))
        wait_for(lambda: psql(cluster.postgres, "SELECT count(*) FROM jobs WHERE state = 'succeeded'")[0][0] == "6",
                 300, step=0.25, what="every job to succeed")
        self.assertEqual(sorted(r[0] for r in psql(cluster.postgres, "SELECT id FROM jobs")), sorted(ids))


if __name__ == "__main__":
    unittest.main()
