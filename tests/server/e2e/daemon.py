"""Shared harness of the end-to-end tests of `devsurf serve`: a daemon on an ephemeral port in a
fresh data directory, driven by an independent client (Python's websockets from Debian's
python3-websockets, and urllib). Every `test_*.py` in this folder is its own CTest entry.

Run one: /usr/bin/python3 -m unittest tests/server/e2e/test_protocol.py   (DEVSURF_BIN = devsurf)
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

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
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
