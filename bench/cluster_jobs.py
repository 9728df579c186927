#!/usr/bin/env python3
"""Wall time of a batch of jobs on one daemon and on three behind HAProxy (issue 18,
docs/scaling.md): the same N jobs (a 200-point strip, 60 iterations each) submitted through the
cluster's port, timed from the first submission to the last result, median of R runs. Each
configuration is a fresh scripts/cluster_local.py cluster (PostgreSQL with its default
durability). Job workers per daemon: --job-workers (default 1).

  /usr/bin/python3 bench/cluster_jobs.py [--jobs 200] [--runs 3] [--job-workers 1]
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "server", "cluster"))
from cluster_testing import Cluster, http, psql  # noqa: E402
from test_cluster_jobs import job_scene  # noqa: E402


def run_once(nodes, jobs, workers, kill_one=False):
    directory = tempfile.mkdtemp(prefix="devsurf-bench-cluster-")
    os.chmod(directory, 0o755)
    cluster = Cluster(directory, nodes=nodes, port=0, lease_ms=2000,
                      extra=["--max-jobs", str(jobs + 10), "--job-workers", str(workers)])
    try:
        cluster.start()
        scene = job_scene()
        start = time.monotonic()
        for k in range(jobs):
            status, _, body = http(cluster.url("/api/jobs"), "POST", scene, {"Idempotency-Key": f"b{k}"})
            assert status == 202, body
        killed = False
        while True:
            done = int(psql(cluster.postgres, "SELECT count(*) FROM jobs WHERE state = 'succeeded'")[0][0])
            if kill_one and not killed and done >= jobs // 3:
                cluster.kill("node2")
                killed = True
            if done == jobs:
                return time.monotonic() - start
            time.sleep(0.05)
    finally:
        cluster.stop()
        subprocess.run([os.path.join(HERE, "..", "scripts", "postgres-local.sh"), "destroy",
                        os.path.join(directory, "postgres")], check=False)
        shutil.rmtree(directory, ignore_errors=True)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--jobs", type=int, default=200)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--job-workers", type=int, default=1)
    a = p.parse_args()
    rows = [("1 daemon", 1, False), ("3 daemons", 3, False), ("3 daemons, node2 SIGKILLed at 1/3", 3, True)]
    print(f"{a.jobs} jobs, {a.job_workers} job worker(s) per daemon, {os.cpu_count()} cores, median of {a.runs}")
    print("| configuration | wall time (s) | jobs/s |\n|---|---|---|")
    for name, nodes, kill in rows:
        times = [run_once(nodes, a.jobs, a.job_workers, kill) for _ in range(a.runs)]
        t = statistics.median(times)
        print(f"| {name} | {t:.1f} ({', '.join(f'{x:.1f}' for x in times)}) | {a.jobs / t:.1f} |", flush=True)


if __name__ == "__main__":
    main()
