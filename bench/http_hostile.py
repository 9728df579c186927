#!/usr/bin/env python3
"""Hostile HTTP clients against a running `devsurf serve`, reporting what the daemon did.

  bench/http_hostile.py PORT PID [slowloris|headers|bodies|chunked|all]

* slowloris: 50 connections send a request head a byte at a time and never finish it; meanwhile
  GET /api/health is probed 5 times (10 s timeout each). Prints how many probes were answered.
* headers: requests with 10 000 and 200 000 header lines; prints the status (or the error).
* bodies: ten POST /api/sessions bodies of 16-17 MB (valid JSON arrays of numbers); prints each
  status and the daemon's RSS (VmRSS of PID) after each.
* chunked: a 200 MiB chunked POST body; prints the status and the RSS.

Outcomes, not latencies; the numbers go to the issue note (issue 12, slow clients and limits).
"""
import http.client
import json
import select
import socket
import sys
import threading
import time


def rss_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def health(port, timeout=10.0):
    try:
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
        c.request("GET", "/api/health")
        r = c.getresponse()
        r.read()
        c.close()
        return r.status
    except Exception as e:  # noqa: BLE001 - the kind of failure is the result
        return type(e).__name__


def slowloris(port, count=50, probes=5):
    stop = threading.Event()
    socks = []
    for _ in range(count):
        s = socket.create_connection(("127.0.0.1", port), timeout=10)
        socks.append(s)
    head = b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "

    def drip():
        i = 0
        while not stop.is_set():
            for s in socks:
                try:
                    s.send(head[i:i + 1] if i < len(head) else b"a")
                except OSError:
                    pass
            i += 1
            stop.wait(0.5)

    t = threading.Thread(target=drip, daemon=True)
    t.start()
    time.sleep(2.0)
    results = [health(port) for _ in range(probes)]
    stop.set()
    t.join()
    for s in socks:
        s.close()
    print(f"slowloris x{count}: health probes -> {results}")
    return results


def many_headers(port, lines):
    s = socket.create_connection(("127.0.0.1", port), timeout=30)
    try:
        head = b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"".join(
            b"X-H%d: v\r\n" % i for i in range(lines)) + b"Connection: close\r\n\r\n"
        s.sendall(head)
        data = s.recv(4096)
        return data.split(b"\r\n", 1)[0].decode(errors="replace") or "(closed)"
    except OSError as e:
        return type(e).__name__
    finally:
        s.close()


def post(port, body, timeout=120):
    try:
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
        c.request("POST", "/api/sessions", body=body, headers={"Content-Type": "application/json"})
        r = c.getresponse()
        r.read()
        c.close()
        return r.status
    except Exception as e:  # noqa: BLE001
        return type(e).__name__


def bodies(port, pid):
    print(f"RSS before: {rss_mb(pid):.0f} MB")
    for i in range(10):
        size = 16_000_000 + i * 100_000
        # a scene whose curve has millions of points: many parser nodes per byte
        point = b"[0.5,1.5,2.5],"
        n = (size - 100) // len(point)
        body = (b'{"format":"devsurf-scene","version":1,"model":{"kind":"strip","a":{"degree":3,"points":['
                + point * (n - 1) + b'[0.5,1.5,2.5]]}}}')
        status = post(port, body)
        print(f"body {len(body) / 1e6:.1f} MB -> {status}; RSS {rss_mb(pid):.0f} MB")
    time.sleep(1.0)
    print(f"RSS after ten bodies (+1 s): {rss_mb(pid):.0f} MB")


def chunked(port, pid, total=200 << 20, chunk=1 << 20):
    s = socket.create_connection(("127.0.0.1", port), timeout=60)
    s.sendall(b"POST /api/sessions HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
              b"Transfer-Encoding: chunked\r\n\r\n")
    piece = b"%x\r\n" % chunk + b"1," * (chunk // 2) + b"\r\n"
    sent = 0
    answer = b""
    try:
        while sent < total:
            r, _, _ = select.select([s], [], [], 0)
            if r:
                break
            s.sendall(piece)
            sent += chunk
        if sent >= total:
            s.sendall(b"0\r\n\r\n")
        s.settimeout(120)
        answer = s.recv(4096)
    except OSError as e:
        answer = type(e).__name__.encode()
    s.close()
    line = answer.split(b"\r\n", 1)[0].decode(errors="replace") or "(closed)"
    print(f"chunked body: {sent / (1 << 20):.0f} MiB sent -> {line}; RSS {rss_mb(pid):.0f} MB")
    time.sleep(1.0)
    print(f"RSS after chunked body (+1 s): {rss_mb(pid):.0f} MB")


def main():
    port, pid = int(sys.argv[1]), int(sys.argv[2])
    what = sys.argv[3] if len(sys.argv) > 3 else "all"
    if what in ("slowloris", "all"):
        slowloris(port)
    if what in ("headers", "all"):
        for lines in (10_000, 200_000):
            print(f"{lines} header lines -> {many_headers(port, lines)}")
    if what in ("bodies", "all"):
        bodies(port, pid)
    if what in ("chunked", "all"):
        chunked(port, pid)
    print("health after:", health(port))


if __name__ == "__main__":
    main()
