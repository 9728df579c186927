#!/usr/bin/python3
"""Bystander latency under runaway edits (issue 12, ARCHITECTURE §8: "one edit cannot starve the
others"): a bystander drags a strip of ~10 000 unknowns at 60 messages/s and measures drag → first
iterate latency, first alone (baseline), then while an attacker on other sessions sends, one after
the other, the edits an outside tester used to take the daemon down:

  quasi  set_params mapping degree 9 / 10 000 coefficients  (grew the daemon to 8.8 GB; now `limit`)
  quasi  set_params samples 100 000                          (> 30 s; now `limit`)
  conical set_params np 100 000                               (> 30 s; now `invalid`, the schema)
  strip  drag 10⁶ units away                                  (geometry at 5·10⁶; now `invalid`)
  REST   POST /api/sessions with the runaway quasi scene      (now 400 `limit`)

With --heavy the attacker also sends conical np = nq = 10 000 (within the schema, ~45 s of work):
it runs until the session's time budget (--session-time-budget-ms, default 5 s) stops it with
`time_budget`, holding one session worker and one core meanwhile.

The attacker sends --attack-rate edits per second (default 20; 0 = each as soon as the last is
answered, a flood that the daemon's per-connection --message-rate, 200/s by default, answers with
`rate_limited` beyond its burst). The daemon runs with its default limits.

Reports p50/p99 of the bystander at baseline and under attack (goal: within 2× of baseline), the
attacker's time to each answer, and the daemon's resident memory before and after.

Usage: bench/bystander_latency.py [--bin build/server/devsurf] [--seconds 20] [--spans 370] [--heavy]
       [--attack-rate 20]
Needs Debian's python3-websockets (scripts/setup.sh installs it).
"""
import argparse
import asyncio
import json
import os
import re
import shutil
import statistics
import sys
import tempfile
import time
import subprocess
import urllib.error
import urllib.request

import websockets

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ws_latency import ROOT, create, drag_client, percentile, strip_scene  # noqa: E402


def start_daemon(binary, data):
    """The daemon with its default limits (message rate, budgets)."""
    proc = subprocess.Popen([binary, "serve", "--port", "0", "--data", data],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    port = int(re.search(r":(\d+)/", proc.stdout.readline()).group(1))
    return proc, port


def example(name):
    with open(os.path.join(ROOT, "examples", name)) as f:
        return json.load(f)


def memory_mib(pid, field):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def runaway_quasi_scene():
    scene = example("quasi-strip-twisted.json")
    scene["model"]["mapping"] = {"degree": 9, "coefficients": 10000}
    return scene


async def joined(port, session):
    ws = await websockets.connect(f"ws://127.0.0.1:{port}/ws", max_size=None)
    await ws.send(json.dumps({"type": "join", "session": session["id"], "token": session["edit_token"]}))
    while json.loads(await ws.recv())["type"] != "state":
        pass
    return ws


async def answer(ws, op, timeout=120.0):
    end = time.monotonic() + timeout
    while True:
        m = json.loads(await asyncio.wait_for(ws.recv(), end - time.monotonic()))
        if (m.get("op") == op and m["type"] in ("ack", "error")) or m.get("code") == "rate_limited":
            return m


def post_session(port, scene):
    req = urllib.request.Request(f"http://127.0.0.1:{port}/api/sessions", data=json.dumps(scene).encode(),
                                 headers={"Content-Type": "application/json"}, method="POST")
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            return r.status, json.load(r)
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"{}")


async def attacker(port, sessions, until, heavy, rate, answers):
    """Sends the runaway edits one after the other until `until`; answers[name] = [(ms, code)…]."""
    quasi = await joined(port, sessions["quasi"])
    conical = await joined(port, sessions["conical"])
    strip = await joined(port, sessions["strip"])
    far = {"type": "drag", "target": {"curve": "b", "index": 6}, "position": [1e6, 0.0, 0.0]}
    attacks = [
        ("quasi mapping 9/10000", quasi, {"type": "set_params", "params": {"mapping": {"degree": 9, "coefficients": 10000}}}),
        ("quasi samples 100000", quasi, {"type": "set_params", "params": {"samples": 100000}}),
        ("conical np 100000", conical, {"type": "set_params", "params": {"np": 100000}}),
        ("strip drag 1e6 away", strip, far),
        ("POST runaway session", None, None),
    ]
    if heavy:
        attacks.append(("conical np=nq=10000", conical, {"type": "set_params", "params": {"np": 10000, "nq": 10000}}))
    k = 0
    while time.monotonic() < until:
        name, ws, message = attacks[k % len(attacks)]
        k += 1
        start = time.monotonic()
        if ws is None:
            status, body = await asyncio.to_thread(post_session, port, runaway_quasi_scene())
            code = f"{status} {body.get('error', {}).get('code', '')}"
        else:
            op = f"attack-{k}"
            await ws.send(json.dumps(dict(message, op=op)))
            m = await answer(ws, op)
            code = m.get("code", m["type"])
        answers.setdefault(name, []).append(((time.monotonic() - start) * 1000.0, code))
        if rate > 0:
            await asyncio.sleep(max(0.0, start + 1.0 / rate - time.monotonic()))
    for ws in (quasi, conical, strip):
        await ws.close()


def run(binary, spans, seconds, heavy, rate):
    data = tempfile.mkdtemp(prefix="devsurf-bystander-")
    proc, port = start_daemon(binary, data)
    try:
        bystander = create(port, strip_scene(spans))
        sessions = {"quasi": create(port, example("quasi-strip-twisted.json")),
                    "conical": create(port, example("conical-strip-hull.json"))}
        strip = example("strip-lifted-corner.json")
        strip["model"].pop("handles", None)
        sessions["strip"] = create(port, strip)

        def drag_phase(label, attack):
            latencies, counts, errors, answers = [], [0], [], {}
            rss_before = memory_mib(proc.pid, "VmRSS")

            async def both():
                tasks = [drag_client(port, bystander["id"], bystander["edit_token"], 0, seconds, 60.0, latencies,
                                     counts, errors)]
                if attack:
                    tasks.append(attacker(port, sessions, time.monotonic() + seconds, heavy, rate, answers))
                await asyncio.gather(*tasks)

            asyncio.run(both())
            rss_after = memory_mib(proc.pid, "VmRSS")
            print(f"{label}: drag → first iterate p50 {percentile(latencies, 50):.1f} ms, "
                  f"p99 {percentile(latencies, 99):.1f} ms ({len(latencies)} drags, "
                  f"{counts[0] / seconds:.1f} iterates/s, bystander errors {len(errors)}); "
                  f"daemon RSS {rss_before:.0f} → {rss_after:.0f} MiB")
            for name, results in answers.items():
                ms = [r[0] for r in results]
                codes = sorted({r[1] for r in results})
                print(f"  {name:24s} ×{len(results):3d}  answered in median {statistics.median(ms):7.1f} ms, "
                      f"max {max(ms):7.1f} ms: {', '.join(codes)}")
            return percentile(latencies, 50), percentile(latencies, 99)

        print(f"bystander: strip of {spans} spans, 60 drags/s for {seconds} s per phase; attacker "
              f"{f'{rate:g} edits/s' if rate > 0 else 'flooding'}{' with --heavy' if heavy else ''}")
        base = drag_phase("baseline    ", False)
        attacked = drag_phase("under attack", True)
        print(f"ratio under attack / baseline: p50 {attacked[0] / base[0]:.2f}×, p99 {attacked[1] / base[1]:.2f}× "
              f"(goal ≤ 2×); daemon peak RSS (VmHWM) {memory_mib(proc.pid, 'VmHWM'):.0f} MiB")
    finally:
        proc.terminate()
        proc.wait()
        shutil.rmtree(data, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "server", "devsurf"))
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--spans", type=int, default=370)
    parser.add_argument("--heavy", action="store_true", help="also conical np = nq = 10 000 (runs to the time budget)")
    parser.add_argument("--attack-rate", type=float, default=20.0, help="attacker edits per second (0: flood)")
    args = parser.parse_args()
    run(args.bin, args.spans, args.seconds, args.heavy, args.attack_rate)


if __name__ == "__main__":
    main()
