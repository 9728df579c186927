#!/usr/bin/python3
"""Interactive-path benchmarks of `devsurf serve` on loopback (ARCHITECTURE.md §7):

  drag   — drag → first streamed iterate latency and iterates per second for one client on a
           strip of ~10 000 unknowns (budget ≤ 30 ms, ≥ 30 iterates/s);
  drag-composite — the same on a composite of ~10 000 unknowns: bench/composite_iteration's
           parallel-crease sheet (--strips 10 --spans 40: 9 879 unknowns without development),
           its last vertex dragged up and down;
  load   — S sessions × C clients dragging for T seconds: p50/p99 drag → iterate latency,
           iterates received, daemon memory (VmHWM), errors (must be 0).

Usage: bench/ws_latency.py [--bin build/server/devsurf] [drag|drag-composite|load|all] [--normal-splines]
       [--development] [--sessions 50]
       [--clients 4] [--seconds 60] [--spans 370] [--strips 10]
Needs Debian's python3-websockets (scripts/setup.sh installs it).
"""
import argparse
import asyncio
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import time
import urllib.request

import websockets

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def start_daemon(binary, data):
    proc = subprocess.Popen([binary, "serve", "--port", "0", "--data", data, "--max-sessions", "1000",
                             "--message-rate", "1000", "--max-connections-per-address", "4096",
                             "--max-connections", "8192"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    port = int(re.search(r":(\d+)/", proc.stdout.readline()).group(1))
    return proc, port


def strip_scene(spans):
    n = spans + 3
    a, b = [], []
    for i in range(n):
        t = math.radians(20.0) * i / (n - 1)
        x = 10.0 * i / (n - 1)
        a.append([x, 0.0, 0.0])
        b.append([x, math.cos(t), math.sin(t)])
    return {"format": "devsurf-scene", "version": 1, "name": f"bench strip {spans} spans",
            "model": {"kind": "strip", "a": {"degree": 3, "points": a}, "b": {"degree": 3, "points": b},
                      "fixed": [{"curve": "a", "index": 0}, {"curve": "b", "index": 0}]},
            "solver": {"fairness": 0.01, "regularization": 0.01}}


def composite_sheet_scene(strips, spans, normal_splines=False, development=False):
    """bench/composite_iteration.cpp's parallelCreaseSheet as a scene: strips + 1 wavy cubic S
    edges along y (x = i + 0.2 sin 2πt, y = 4t), the interior ones curved folds, rulings across
    their ends; the first edge's ends and middle point held, a handle lifting the far corner."""
    n = spans + 3
    vertices, edges, faces = [], [], []
    for i in range(strips + 1):
        pts = [[i + 0.2 * math.sin(2 * math.pi * k / (n - 1)), 4.0 * k / (n - 1), 0.0] for k in range(n)]
        vertices += [pts[0], pts[-1]]
        edge = {"v": [2 * i, 2 * i + 1], "type": "S", "degree": 3, "points": pts[1:-1]}
        if 0 < i < strips:
            edge["crease"] = "fold"
        edges.append(edge)
    edges += [{"v": [2 * j, 2 * j + 2], "type": "R"} for j in range(strips)]
    edges += [{"v": [2 * j + 3, 2 * j + 1], "type": "R"} for j in range(strips)]
    faces = [[strips + 1 + j, j + 1, 2 * strips + 1 + j, j] for j in range(strips)]
    corner = 2 * strips + 1
    scene = {"format": "devsurf-scene", "version": 1, "name": f"bench composite {strips} × {spans}",
            "model": {"kind": "composite", "vertices": vertices, "edges": edges, "faces": faces,
                      "fixed": [{"vertex": 0}, {"vertex": 1}, {"edge": 0, "index": n // 2}],
                      "handles": [{"vertex": corner, "position": [vertices[corner][0] - 0.1, vertices[corner][1], 0.5]}]},
            "solver": {"normal_splines": normal_splines}}
    if development:  # a developed sheet: its drags hold the tighter band with correction steps
        scene["model"]["development"] = {"samples": 4}
    return scene


def create(port, scene):
    req = urllib.request.Request(f"http://127.0.0.1:{port}/api/sessions", data=json.dumps(scene).encode(),
                                 headers={"Content-Type": "application/json"}, method="POST")
    return json.load(urllib.request.urlopen(req))


async def drag_client(port, session, token, index, seconds, rate, latencies, counts, errors):
    async with websockets.connect(f"ws://127.0.0.1:{port}/ws", max_size=None) as ws:
        await ws.send(json.dumps({"type": "join", "session": session, "token": token}))
        state = json.loads(await ws.recv())
        model = state["scene"]["model"]
        if model["kind"] == "composite":  # the vertex before the lifted corner (the handle's is taken)
            target = {"vertex": len(model["vertices"]) - 3}
            base = model["vertices"][target["vertex"]]
        else:
            n = len(model["b"]["points"])
            target = {"curve": "b", "index": n - 1 - (index % 3)}
            base = model["b"]["points"][target["index"]]
        sent_at = {}      # op → send time
        op_seq = {}       # seq → send time of the op it acknowledged
        done = time.monotonic() + seconds

        async def reader():
            while True:
                m = json.loads(await ws.recv())
                if m["type"] == "ack" and m.get("op") in sent_at:
                    op_seq.setdefault(m["seq"], sent_at.pop(m["op"]))
                elif m["type"] == "iterate":
                    counts[0] += 1
                    t0 = op_seq.pop(m["seq"], None)
                    if t0 is not None:
                        latencies.append((time.monotonic() - t0) * 1000.0)
                elif m["type"] == "error":
                    errors.append(m)

        task = asyncio.create_task(reader())
        k = 0
        while time.monotonic() < done:
            k += 1
            z = base[2] + 0.5 * math.sin(k / 10.0)
            sent_at[f"{index}-{k}"] = time.monotonic()
            await ws.send(json.dumps({"type": "drag", "op": f"{index}-{k}", "target": target,
                                      "position": [base[0], base[1], z]}))
            await asyncio.sleep(1.0 / rate)
        await ws.send(json.dumps({"type": "drag_end", "target": target}))
        await asyncio.sleep(0.3)
        task.cancel()


def percentile(values, p):
    if not values:
        return float("nan")
    values = sorted(values)
    return values[min(len(values) - 1, int(p / 100.0 * len(values)))]


def vm_hwm_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def run_drag(binary, spans, seconds, strips=0, normal_splines=False, development=False):
    data = tempfile.mkdtemp(prefix="devsurf-bench-")
    proc, port = start_daemon(binary, data)
    try:
        s = create(port, composite_sheet_scene(strips, spans, normal_splines, development) if strips else strip_scene(spans))
        latencies, counts, errors = [], [0], []
        asyncio.run(drag_client(port, s["id"], s["edit_token"], 0, seconds, 60.0, latencies, counts, errors))
        unknowns = json.load(urllib.request.urlopen(
            urllib.request.Request(f"http://127.0.0.1:{port}/api/sessions/{s['id']}",
                                   headers={"Authorization": "Bearer " + s["view_token"]})))["metrics"]["unknowns"]
        what = f"composite sheet of {strips} strips × {spans} spans" if strips else f"strip of {spans} spans"
        if strips and normal_splines:
            what += " with normal splines"
        if strips and development:
            what += " with a development"
        print(f"drag: {what} ({unknowns:.0f} unknowns), 60 drags/s for {seconds} s")
        print(f"  drag → first iterate: median {statistics.median(latencies):.1f} ms, "
              f"p99 {percentile(latencies, 99):.1f} ms (budget ≤ 30 ms); {len(latencies)} samples")
        print(f"  iterates received: {counts[0] / seconds:.1f} per second (budget ≥ 30); errors {len(errors)}")
    finally:
        proc.terminate()
        proc.wait()
        shutil.rmtree(data, ignore_errors=True)


def run_load(binary, sessions, clients, seconds):
    data = tempfile.mkdtemp(prefix="devsurf-load-")
    proc, port = start_daemon(binary, data)
    try:
        with open(os.path.join(ROOT, "examples", "strip-lifted-corner.json")) as f:
            scene = json.load(f)
        scene["model"].pop("handles", None)
        ids = [create(port, scene) for _ in range(sessions)]
        latencies, counts, errors = [], [0], []

        async def all_clients():
            await asyncio.gather(*[drag_client(port, s["id"], s["edit_token"], c, seconds, 10.0, latencies, counts, errors)
                                   for s in ids for c in range(clients)])

        start = time.monotonic()
        asyncio.run(all_clients())
        elapsed = time.monotonic() - start
        print(f"load: {sessions} sessions × {clients} clients, 10 drags/s each, {seconds} s")
        print(f"  drag → iterate latency p50 {percentile(latencies, 50):.1f} ms, p99 {percentile(latencies, 99):.1f} ms "
              f"({len(latencies)} samples); {counts[0] / elapsed:.0f} iterates/s delivered in all")
        print(f"  daemon peak memory (VmHWM) {vm_hwm_mb(proc.pid):.0f} MiB; errors {len(errors)}")
        if errors:
            print("  first error:", errors[0])
    finally:
        proc.terminate()
        proc.wait()
        shutil.rmtree(data, ignore_errors=True)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("what", nargs="?", default="all", choices=["drag", "drag-composite", "load", "all"])
    p.add_argument("--bin", default=os.path.join(ROOT, "build", "server", "devsurf"))
    p.add_argument("--spans", type=int, default=None, help="strip: 370 spans; composite sheet: 40 spans per S edge")
    p.add_argument("--strips", type=int, default=10, help="strips of the composite sheet")
    p.add_argument("--normal-splines", action="store_true", help="composite sheet: solver.normal_splines")
    p.add_argument("--development", action="store_true",
                   help="composite sheet: a development (4 samples), whose drags take correction steps")
    p.add_argument("--sessions", type=int, default=50)
    p.add_argument("--clients", type=int, default=4)
    p.add_argument("--seconds", type=int, default=60)
    a = p.parse_args()
    if a.what in ("drag", "all"):
        run_drag(a.bin, a.spans or 370, min(a.seconds, 20))
    if a.what in ("drag-composite", "all"):
        run_drag(a.bin, a.spans or 40, min(a.seconds, 20), strips=a.strips, normal_splines=a.normal_splines,
                 development=a.development)
    if a.what in ("load", "all"):
        run_load(a.bin, a.sessions, a.clients, a.seconds)


if __name__ == "__main__":
    main()
