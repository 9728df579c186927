"""Issue 18: collaborative sessions on three daemons behind HAProxy. 20 sessions, two clients
each dragging through HAProxy (`/ws?session=ID`, routed by consistent hashing); the daemon that
holds the most sessions is SIGKILLed. Every one of its sessions is served again by another daemon
within 5 s (the lease is 2 s), and every edit any client had acknowledged is in the state the
reconnected clients get, and in the store (read back with psql)."""
import asyncio
import json
import re
import time
import unittest
import urllib.request

import websockets

from cluster_testing import example, http, psql, start_cluster, wait_for

SESSIONS = 20


class Client:
    """One participant: joins through HAProxy, drags, remembers every acknowledged seq, and
    reconnects (as the web app does) when its connection drops or the session is not served yet."""

    def __init__(self, cluster, session, name, index):
        self.cluster, self.session, self.name, self.index = cluster, session, name, index
        self.ws = None
        self.acked = []            # seqs of acknowledged edits
        self.state_seq = None      # seq of the last state message (a join)
        self.joined_at = None
        self.op = 0

    async def join(self, deadline):
        url = f"ws://127.0.0.1:{self.cluster.port}/ws?session={self.session['id']}"
        while time.monotonic() < deadline:
            try:
                ws = await websockets.connect(url, max_size=None, open_timeout=5)
                await ws.send(json.dumps({"type": "join", "session": self.session["id"],
                                          "token": self.session["edit_token"], "name": self.name}))
                first = json.loads(await asyncio.wait_for(ws.recv(), 10))
                if first["type"] == "state":
                    self.ws, self.state_seq, self.joined_at = ws, first["seq"], time.monotonic()
                    return first
                assert first["type"] == "error" and first["code"] == "unavailable", first
                await ws.close()
            except (OSError, websockets.exceptions.WebSocketException, asyncio.TimeoutError):
                pass
            await asyncio.sleep(0.25)
        raise AssertionError(f"{self.name} could not rejoin {self.session['id']}")

    async def drag_for(self, seconds):
        """Drags the strip's corner up and down; records acks until the connection drops."""
        end = time.monotonic() + seconds
        try:
            while time.monotonic() < end:
                self.op += 1
                z = 0.5 + 0.4 * ((self.op % 10) / 10.0)
                await self.ws.send(json.dumps({"type": "drag", "op": self.op,
                                               "target": {"curve": "b", "index": 6 - self.index},
                                               "position": [6.0 - self.index, 1.0, z]}))
                stop = time.monotonic() + 0.3
                while time.monotonic() < stop:
                    try:
                        m = json.loads(await asyncio.wait_for(self.ws.recv(), max(0.01, stop - time.monotonic())))
                    except asyncio.TimeoutError:
                        break
                    if m["type"] == "ack":
                        self.acked.append(m["seq"])
        except websockets.exceptions.ConnectionClosed:
            self.ws = None


class SessionsOnThreeDaemonsTest(unittest.TestCase):
    def test_sessions_of_a_killed_daemon_are_served_again_within_5_s_with_every_acknowledged_edit(self):
        cluster = start_cluster(self, nodes=3, lease_ms=2000)
        scene = example("strip-lifted-corner.json")
        scene["model"].pop("handles", None)
        sessions = []
        for _ in range(SESSIONS):
            status, _, body = http(cluster.url("/api/sessions"), "POST", scene)
            self.assertEqual(status, 201, body)
            sessions.append(body)

        async def run():
            clients = [Client(cluster, s, f"c{k}-{i}", i) for k, s in enumerate(sessions) for i in range(2)]
            deadline = time.monotonic() + 60
            await asyncio.gather(*(c.join(deadline) for c in clients))
            await asyncio.gather(*(c.drag_for(3.0) for c in clients))

            holders = dict((r[0], r[1]) for r in psql(cluster.postgres, "SELECT id, lease_owner FROM sessions"))
            per_node = {}
            for s in sessions:
                per_node.setdefault(holders[s["id"]], []).append(s["id"])
            victim = max(per_node, key=lambda n: len(per_node[n]))
            moved = set(per_node[victim])
            self.assertGreaterEqual(len(moved), 2, per_node)
            # Each session is held by the node HAProxy routes it to (both its clients are there).
            for s in sessions:
                self.assertIsNotNone(holders[s["id"]])

            # Drag on while the victim dies.
            dragging = asyncio.gather(*(c.drag_for(2.0) for c in clients))
            await asyncio.sleep(0.7)
            cluster.kill(victim)
            killed_at = time.monotonic()
            await dragging
            acked_before = {s["id"]: max([a for c in clients if c.session is s for a in c.acked], default=0)
                            for s in sessions}

            for c in clients:
                if c.ws is not None:
                    await c.ws.close()
                c.ws = None
            rejoin_deadline = time.monotonic() + 30
            await asyncio.gather(*(c.join(rejoin_deadline) for c in clients))
            joined = {id(c): (c.state_seq, c.joined_at) for c in clients}

            async def one_more():  # a session that moved takes edits again
                c = next(c for c in clients if c.session["id"] in moved)
                for _ in range(5):
                    # A client that rejoined before HAProxy saw the victim down may have been sent to
                    # another node than the session's place on the ring; the session then moves once
                    # more (a handover) and the client reconnects, as the web app does.
                    if c.ws is None:
                        await c.join(time.monotonic() + 30)
                    await c.drag_for(1.0)
                    if c.ws is not None:
                        await c.ws.close()
                        break
                for other in clients:
                    if other.ws is not None:
                        await other.ws.close()
                return c
            after = await one_more()
            return clients, joined, moved, killed_at, acked_before, victim, after

        clients, joined, moved, killed_at, acked_before, victim, after = asyncio.run(run())
        holders = dict((r[0], r[1]) for r in psql(cluster.postgres, "SELECT id, lease_owner FROM sessions"))
        slowest = 0.0
        for c in clients:
            sid = c.session["id"]
            # Every acknowledged edit is in the state the reconnected client got…
            state_seq, joined_at = joined[id(c)]
            self.assertGreaterEqual(state_seq, acked_before[sid], f"{sid}: acknowledged edits lost")
            if sid in moved:
                self.assertNotEqual(holders[sid], victim)
                slowest = max(slowest, joined_at - killed_at)
        # … served again within 5 s of the kill (reconnect back-off included).
        self.assertLess(slowest, 5.0, f"a session of {victim} took {slowest:.2f} s to be served again")
        print(f"{len(moved)} sessions of {victim} served again by other daemons, the last {slowest:.2f} s after the kill")
        # … and in the store: the last stored seq of every session covers every acknowledged one.
        stored = dict((r[0], int(r[1])) for r in psql(cluster.postgres, "SELECT id, last_seq FROM sessions"))
        for sid, acked in acked_before.items():
            self.assertGreater(acked, 0, f"{sid}: no drag was acknowledged before the kill")
            self.assertGreaterEqual(stored[sid], acked, sid)

        self.assertGreater(max(after.acked), acked_before[after.session["id"]], "a moved session takes edits again")
        # Each surviving node's own metrics: its id, and the sessions it took over.
        adopted = 0
        for n in cluster.nodes:
            if n["id"] == victim:
                continue
            with urllib.request.urlopen(f"http://127.0.0.1:{n['port']}/api/metrics", timeout=10) as r:
                text = r.read().decode()
            self.assertIn(f'devsurf_node_info{{node="{n["id"]}",store="postgresql"}} 1', text)
            adopted += int(re.search(r'devsurf_node_sessions_total\{event="adopted"\} (\d+)', text).group(1))
        self.assertGreaterEqual(adopted, len(moved), "the survivors adopted every session of the victim")


if __name__ == "__main__":
    unittest.main()
