"""Shared harness of the multi-daemon tests (issue 18): a cluster of scripts/cluster_local.py
(private PostgreSQL, daemons, HAProxy) in a temporary directory, a REST client through HAProxy
or straight to one node, and a reader of the PostgreSQL store through psql (an independent
client, Debian's)."""
import json
import os
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from cluster_local import Cluster  # noqa: E402,F401  (re-exported for bench/cluster_jobs.py)

EXAMPLES = os.path.join(ROOT, "examples")


def http(url, method="GET", body=None, headers=None, timeout=30):
    data = None if body is None else json.dumps(body).encode()
    headers = dict(headers or {})
    if data is not None:
        headers.setdefault("Content-Type", "application/json")
    req = urllib.request.Request(url, data=data, method=method, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            raw = r.read()
            return r.status, dict(r.headers), (json.loads(raw) if raw else None)
    except urllib.error.HTTPError as e:
        raw = e.read()
        try:
            return e.code, dict(e.headers), json.loads(raw)
        except ValueError:
            return e.code, dict(e.headers), raw


def psql(uri, sql):
    """Rows of a query as lists of strings (psql -tA, fields separated by \\x1f)."""
    out = subprocess.run(["psql", uri, "-X", "-q", "-t", "-A", "-F", "\x1f", "-v", "ON_ERROR_STOP=1", "-c", sql],
                         check=True, capture_output=True, text=True).stdout
    return [line.split("\x1f") for line in out.splitlines() if line]


def example(name):
    with open(os.path.join(EXAMPLES, name)) as f:
        return json.load(f)


def start_cluster(test, nodes=3, lease_ms=2000, extra=()):
    """A started cluster in a fresh directory, destroyed when the test case ends."""
    directory = tempfile.mkdtemp(prefix="devsurf-cluster-")
    os.chmod(directory, 0o755)  # the PostgreSQL server (account postgres when run as root) enters it
    cluster = Cluster(directory, nodes=nodes, port=0, lease_ms=lease_ms, fast=True, extra=list(extra))

    def destroy():
        cluster.stop()
        subprocess.run([os.path.join(ROOT, "scripts", "postgres-local.sh"), "destroy",
                        os.path.join(directory, "postgres")], check=False)
        subprocess.run(["rm", "-rf", directory], check=False)

    test.addCleanup(destroy)
    cluster.start()
    return cluster


def wait_for(predicate, timeout, step=0.1, what="condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(step)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")
