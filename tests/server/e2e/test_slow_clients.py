"""Issue 12: slow, idle and oversized HTTP clients can neither stall nor exhaust the daemon.

Outcomes, never latencies: every probe has a generous timeout (10 s); before the asynchronous
transport, the probes under slowloris never answered at all.
"""
import asyncio
import json
import select
import socket
import threading
import time
import http.client

from daemon import DaemonTestCase, drag, join, recv_until

# Run against SQLite alone (tests/CMakeLists.txt): what is tested is the HTTP transport; its sessions and
# edits use the store as every module's do.
ONE_STORE_IS_ENOUGH = True

MB = 1 << 20


def rss_mb(pid, field="VmRSS"):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError(f"no {field} for pid {pid}")


def sanitized(pid):
    """Whether the daemon runs under ASan/TSan, whose allocators keep freed memory on purpose."""
    with open(f"/proc/{pid}/maps") as f:
        return any("libasan" in line or "libtsan" in line for line in f)


def health(port, timeout=10.0):
    """The status of GET /api/health, or the name of the exception (a timeout, a reset)."""
    try:
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
        c.request("GET", "/api/health")
        r = c.getresponse()
        r.read()
        c.close()
        return r.status
    except (OSError, http.client.HTTPException) as e:
        return type(e).__name__


def read_response(sock, timeout=30.0):
    """(status, body) of one response on a raw socket whose request was sent."""
    sock.settimeout(timeout)
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = sock.recv(65536)
        if not chunk:
            break
        data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    if not head.startswith(b"HTTP/1.1 "):
        return 0, head
    length = 0
    for line in head.split(b"\r\n")[1:]:
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"content-length":
            length = int(value)
    while len(body) < length:
        chunk = sock.recv(65536)
        if not chunk:
            break
        body += chunk
    return int(head[9:12]), body


class SlowClientsTest(DaemonTestCase):
    """Fifty connections send request heads a byte at a time and never finish them."""
    PREFIX = "devsurf-slow-"
    # The slow connections must outlive the test: a head deadline longer than the test.
    DAEMON_ARGS = ("--header-timeout-ms", "300000")

    def test_fifty_slowloris_connections_stall_neither_health_nor_a_websocket_drag(self):
        port = self.daemon.port
        slow = [socket.create_connection(("127.0.0.1", port), timeout=10) for _ in range(50)]
        head = b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "
        stop = threading.Event()
        send_errors = []

        def drip():
            i = 0
            while not stop.is_set():
                byte = head[i:i + 1] if i < len(head) else b"a"
                for s in slow:
                    try:
                        s.send(byte)
                    except OSError as e:
                        send_errors.append(e)
                i += 1
                stop.wait(0.2)

        dripper = threading.Thread(target=drip, daemon=True)
        dripper.start()
        try:
            time.sleep(1.0)  # every slow connection has begun its head
            self.assertEqual([health(port) for _ in range(5)], [200] * 5)

            demo = self.daemon.json("GET", "/api/sessions")[2]["sessions"][0]

            async def drag_demo():
                ws, state = await join(port, demo["id"], demo["edit_token"])
                self.assertEqual((state["type"], state["role"]), ("state", "edit"))
                for k in range(1, 7):
                    await ws.send(drag(k, 1.8 + 0.05 * k))
                    await asyncio.sleep(0.02)
                await ws.send(json.dumps({"type": "drag_end", "op": "end",
                                          "target": {"curve": "b", "index": 6}}))
                seen = await recv_until(ws, lambda m: m["type"] in ("solved", "error"), timeout=60)
                await ws.close()
                return seen

            seen = asyncio.run(drag_demo())
            self.assertEqual(seen[-1]["type"], "solved", seen[-1])
            acks = {m["op"] for m in seen if m["type"] == "ack"}
            self.assertEqual(acks, {1, 2, 3, 4, 5, 6, "end"})
            self.assertEqual(health(port), 200)
        finally:
            stop.set()
            dripper.join()
        # All along, the slow connections were open and unanswered: the probes above were served
        # beside them, not after them.
        self.assertEqual(send_errors, [])
        for s in slow:
            s.setblocking(False)
            with self.assertRaises(BlockingIOError):
                s.recv(1)
            s.close()


class OversizedRequestsTest(DaemonTestCase):
    """Requests over the head, field and body limits are refused with a JSON error, and the memory
    they took is given back."""
    PREFIX = "devsurf-oversized-"

    def assert_error(self, status, body, expected_status, code):
        self.assertEqual(status, expected_status, body[:200])
        self.assertEqual(json.loads(body)["error"]["code"], code)

    def test_ten_thousand_header_lines_are_431(self):
        s = socket.create_connection(("127.0.0.1", self.daemon.port), timeout=30)
        lines = b"".join(b"X-Line-%d: v\r\n" % i for i in range(10000))
        s.sendall(b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\n" + lines + b"\r\n")
        status, body = read_response(s)
        s.close()
        self.assert_error(status, body, 431, "too_large")
        self.assertEqual(health(self.daemon.port), 200)

    def test_a_chunked_body_of_200_mib_is_413_and_memory_stays_bounded(self):
        pid = self.daemon.proc.pid
        s = socket.create_connection(("127.0.0.1", self.daemon.port), timeout=60)
        s.sendall(b"POST /api/sessions HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                  b"Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n")
        piece = b"%x\r\n" % MB + b" " * MB + b"\r\n"
        sent = 0
        try:
            while sent < 200 * MB and not select.select([s], [], [], 0)[0]:
                s.sendall(piece)
                sent += MB
            if sent == 200 * MB:
                s.sendall(b"0\r\n\r\n")
        except OSError:
            pass  # the daemon may stop reading once it has answered; the answer is still there
        status, body = read_response(s)
        s.close()
        self.assert_error(status, body, 413, "too_large")
        self.assertIn("16777216 bytes", json.loads(body)["error"]["message"])
        if not sanitized(pid):
            self.assertLess(rss_mb(pid, "VmHWM"), 600, f"peak RSS after a {sent // MB} MiB chunked body")
        self.assertEqual(health(self.daemon.port), 200)

    def test_large_rejected_bodies_leave_no_lasting_memory(self):
        pid = self.daemon.proc.pid
        point = b"[0.5,1.5,2.5],"
        statuses = []
        for i in range(10):
            size = 16_000_000 + i * 100_000  # 16.0 … 16.9 MB: the last two exceed --max-body
            n = (size - 100) // len(point)
            body = (b'{"format":"devsurf-scene","version":1,"model":{"kind":"strip","a":{"degree":3,"points":['
                    + point * (n - 1) + b"[0.5,1.5,2.5]]}}}")
            c = http.client.HTTPConnection("127.0.0.1", self.daemon.port, timeout=120)
            try:
                c.request("POST", "/api/sessions", body=body, headers={"Content-Type": "application/json"})
                r = c.getresponse()
                statuses.append(r.status)
                r.read()
            except OSError as e:
                statuses.append(type(e).__name__)
            finally:
                c.close()
        self.assertEqual(statuses, [400] * 8 + [413] * 2)
        time.sleep(0.5)
        if not sanitized(pid):
            self.assertLess(rss_mb(pid), 600, "RSS after ten 16-17 MB bodies")
        self.assertEqual(health(self.daemon.port), 200)
