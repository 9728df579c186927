"""Shared harness of the end-to-end tests of `devsurf serve`: a daemon on an ephemeral port in a
fresh data directory, driven by an independent client (Python's websockets from Debian's
python3-websockets, and urllib). Every `test_*.py` in this folder is its own CTest entry.

Run one: /usr/bin/python3 -m unittest tests/server/e2e/test_protocol.py   (DEVSURF_BIN = devsurf)

The store: SQLite in the data directory, or with DEVSURF_TEST_STORE=postgresql a schema of its own
(named after the data directory) in the PostgreSQL database DEVSURF_TEST_POSTGRES (CTest runs
every test both ways, issue 18). open_store() reads the store behind the daemon's back either way.
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

STORE = os.environ.get("DEVSURF_TEST_STORE", "sqlite")
POSTGRES = os.environ.get("DEVSURF_TEST_POSTGRES", "")
if STORE == "postgresql" and not POSTGRES:
    raise RuntimeError("DEVSURF_TEST_STORE=postgresql needs DEVSURF_TEST_POSTGRES (a libpq URI)")


def postgres_schema(data_dir):
    """The schema that stands for a data directory (a restart on the same directory reopens it)."""
    return "e2e_" + re.sub(r"[^a-z0-9]", "_", os.path.basename(os.path.normpath(data_dir)).lower())


def store_args(data_dir):
    """The serve flags for this data directory's store: --store, and on PostgreSQL a --node-id of
    its own that a restart on the same directory keeps (it takes back the sessions it held)."""
    if STORE != "postgresql":
        return ["--store", data_dir]
    return ["--store", store_location(data_dir), "--node-id", postgres_schema(data_dir)]


def store_location(data_dir):
    """What `devsurf serve --store` gets for this data directory (created on first use)."""
    if STORE != "postgresql":
        return data_dir
    schema = postgres_schema(data_dir)
    subprocess.run(["psql", POSTGRES, "-X", "-q", "-c", f"CREATE SCHEMA IF NOT EXISTS {schema}"],
                   check=True, stdout=subprocess.DEVNULL)
    return POSTGRES + ("&" if "?" in POSTGRES else "?") + "options=-csearch_path%3D" + schema


class _Rows:
    def __init__(self, rows):
        self.rows = rows

    def fetchone(self):
        return self.rows[0] if self.rows else None

    def __iter__(self):
        return iter(self.rows)


class PostgresConnection:
    """The few sqlite3.Connection calls the tests make (execute with ? parameters, fetchone,
    iteration, commit, close), run through psql, Debian's PostgreSQL client: an independent reader
    of the daemon's PostgreSQL store. Each statement commits on its own."""

    FIELD, RECORD, NULL = "\x1f", "\x1e", "\x1d"

    def __init__(self, uri):
        self.uri = uri

    @staticmethod
    def literal(v):
        if v is None:
            return "NULL"
        if isinstance(v, (int, float)):
            return repr(v)
        return "'" + str(v).replace("'", "''") + "'"

    def execute(self, sql, params=()):
        parts = sql.split("?")
        assert len(parts) == len(params) + 1, sql
        text = parts[0] + "".join(self.literal(p) + rest for p, rest in zip(params, parts[1:]))
        out = subprocess.run(["psql", self.uri, "-X", "-q", "-t", "-A", "-F", self.FIELD, "-R", self.RECORD,
                              "-P", "null=" + self.NULL, "-v", "ON_ERROR_STOP=1", "-c", text],
                             check=True, capture_output=True, text=True).stdout
        rows = []
        for record in out.rstrip("\n").split(self.RECORD):
            if record == "":
                continue
            row = tuple(None if f == self.NULL else int(f) if re.fullmatch(r"-?\d+", f) else f
                        for f in record.split(self.FIELD))
            rows.append(row)
        return _Rows(rows)

    def commit(self):
        pass

    def close(self):
        pass


def open_store(data_dir):
    """A connection to the store of a daemon started on data_dir: sqlite3 on DIR/devsurf.db, or
    PostgresConnection on its schema."""
    if STORE == "postgresql":
        return PostgresConnection(store_location(data_dir))
    import sqlite3
    return sqlite3.connect(os.path.join(data_dir, "devsurf.db"))

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
            [BIN, "serve", "--port", "0", "--data", self.data_dir, *store_args(self.data_dir),
             "--demo", DEMO, *self.extra],
            stdout=subprocess.PIPE, stderr=self.log_file(), text=True)
        line = self.proc.stdout.readline()
        m = re.search(r":(\d+)/", line)
        if not m:
            raise RuntimeError("daemon did not start: " + line)
        self.port = int(m.group(1))
        return self

    def log_file(self):
        """The daemon's log: DEVSURF_E2E_LOGS/<data dir name>.log when that is set, else nowhere."""
        logs = os.environ.get("DEVSURF_E2E_LOGS")
        if not logs:
            return subprocess.DEVNULL
        os.makedirs(logs, exist_ok=True)
        return open(os.path.join(logs, os.path.basename(os.path.normpath(self.data_dir)) + ".log"), "a")

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
