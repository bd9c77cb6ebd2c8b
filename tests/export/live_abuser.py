"""The live view's abuser, for tests/export/test_live_abuse.py and the foxglove_abuse
benchmark, run as a process of its own so that what it holds is not in the server's RSS:

    python live_abuser.py PORT IDLE READERS HALF_OPEN

It opens IDLE connections that send nothing, 10 that send part of a handshake, one client per
kind of malformed frame, HALF_OPEN WebSocket connections closed without telling the server
(TCP_REPAIR, where the system allows it) and READERS clients subscribed to everything that never
read. It prints one JSON line once all are open, a second with when the server closed each
idle, partial and malformed connection, then exits at a line on stdin, the system closing what
is left."""

import contextlib
import json
import os
import select
import socket
import sys
import threading
import time

from websockets.sync.client import connect

port, n_idle, n_readers, n_half = (int(a) for a in sys.argv[1:5])
HEAD = (
    b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
    b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
    b"Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n"
)
MASK = b"\x01\x02\x03\x04"
MALFORMED = {
    "unmasked": b"\x81\x05hello",
    "reserved_bit": b"\xc1\x85" + MASK + b"hello",
    "unknown_opcode": b"\x83\x80" + MASK,
    "huge_length": b"\x82\xff" + (1 << 40).to_bytes(8, "big") + MASK + b"x" * 1000,
    "over_limit": b"\x82\xff" + (8 << 20).to_bytes(8, "big") + MASK + b"x" * 65536,
    "long_ping": b"\x89\xfe\x01\x00" + MASK + b"p" * 256,
    "stalled_frame": b"\x82\xfe\x10\x00" + MASK + b"x" * 100,
    "garbage": bytes(range(256)) * 4,
}


def connect_raw():
    s = socket.create_connection(("127.0.0.1", port))
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    return s


def handshake():
    s = connect_raw()
    s.sendall(HEAD)
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(4096)
        if not chunk:
            raise RuntimeError("closed in the handshake")
        head += chunk
    if not head.startswith(b"HTTP/1.1 101"):
        raise RuntimeError(head[:40])
    return s


def closed_after(socks, started, limit=15.0):
    # Seconds from `started` until each socket was closed by the server (None: still open),
    # and whether each got an HTTP 503 first.
    when = {s: None for s in socks}
    busy = {s: False for s in socks}
    while time.perf_counter() - started < limit and any(v is None for v in when.values()):
        ready, _, _ = select.select([s for s, v in when.items() if v is None], [], [], 0.2)
        for s in ready:
            try:
                data = s.recv(65536)
            except OSError:
                data = b""
            if data.startswith(b"HTTP/1.1 503"):
                busy[s] = True
            if not data:
                when[s] = time.perf_counter() - started
    return [when[s] for s in socks], sum(busy.values())


report = {}
started = time.perf_counter()
idle = [connect_raw() for _ in range(n_idle)]
partial = []
for _ in range(10):
    s = connect_raw()
    s.sendall(HEAD[:30])  # a handshake that never ends
    partial.append(s)
malformed = {}
for name, frame in MALFORMED.items():
    s = handshake()
    s.sendall(frame)
    malformed[name] = s
half = []
for _ in range(n_half):
    s = handshake()
    try:
        s.setsockopt(socket.IPPROTO_TCP, 19, 1)  # TCP_REPAIR: close without telling the peer
    except OSError:
        s.close()
        break
    s.close()  # the server's side stays open: a half-open connection
    half.append(1)
report["half_open"] = len(half)
report["half_open_at"] = time.time()
readers, refused_readers = [], 0
stack = contextlib.ExitStack()
for _ in range(n_readers):
    try:
        c = stack.enter_context(connect(f"ws://127.0.0.1:{port}",
                                        subprotocols=["foxglove.sdk.v1"], max_queue=4,
                                        open_timeout=10))  # fmt: skip
    except Exception:
        refused_readers += 1
        continue
    channels = []
    while not channels:
        message = json.loads(c.recv(timeout=10))
        if message.get("op") == "advertise":
            channels = message["channels"]
    c.send(
        json.dumps(
            {
                "op": "subscribe",
                "subscriptions": [
                    {"id": i, "channelId": ch["id"]} for i, ch in enumerate(channels)
                ],
            }
        )
    )
    readers.append(c)  # never read from again
report["readers_served"] = len(readers)
report["readers_refused"] = refused_readers
report["opened_s"] = time.perf_counter() - started
print(json.dumps(report), flush=True)
results = {}
threads = []


def watch(name, socks):
    results[name] = closed_after(socks, started)


for name, socks in (("idle", idle), ("partial", partial), ("malformed", list(malformed.values()))):
    threads.append(threading.Thread(target=watch, args=(name, socks)))
    threads[-1].start()
for t in threads:
    t.join()
for name, (when, busy) in results.items():
    report[name] = {"closed_after_s": when, "busy": busy}
report["malformed_names"] = list(malformed)
print(json.dumps(report), flush=True)
sys.stdin.readline()
os._exit(0)  # the system closes every socket at once
