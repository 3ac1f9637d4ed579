#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# A live-view viewer that stops reading: a WebSocket client (foxglove.websocket.v1) with a 4 KiB
# receive buffer (SO_RCVBUF, set before connecting, so the kernel cannot hide the backlog) that
# subscribes to every advertised channel and then reads nothing for SECONDS. Prints "subscribed N
# channels". Whether fusedetd dropped it the caller reads from the status (live.dropped_slow).
# Usage: slow_viewer.py HOST:PORT SECONDS
import base64, json, os, socket, sys, time

host, port = sys.argv[1].rsplit(":", 1)
seconds = float(sys.argv[2])
s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
s.connect((host, int(port)))
key = base64.b64encode(os.urandom(16)).decode()
s.sendall((f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
           f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n").encode())
data = b""


def read_exact(n):
    global data
    while len(data) < n:
        chunk = s.recv(65536)
        if not chunk:
            raise SystemExit("closed during the handshake")
        data += chunk
    out, data = data[:n], data[n:]
    return out


while b"\r\n\r\n" not in data:
    data += s.recv(4096)
head, data = data.split(b"\r\n\r\n", 1)
if b" 101 " not in head.split(b"\r\n")[0]:
    raise SystemExit("handshake refused: " + head.decode(errors="replace"))


def read_message():  # one message: its frames (a first one, continuations up to FIN) joined
    opcode, payload = None, b""
    while True:
        b0, b1 = read_exact(2)
        n = b1 & 0x7F
        if n == 126:
            n = int.from_bytes(read_exact(2), "big")
        elif n == 127:
            n = int.from_bytes(read_exact(8), "big")
        opcode = opcode if (b0 & 0x0F) == 0 else b0 & 0x0F
        payload += read_exact(n)
        if b0 & 0x80:
            return opcode, payload


def send_text(text):
    payload, mask = text.encode(), os.urandom(4)
    n = len(payload)
    header = bytes([0x81]) + (bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + n.to_bytes(2, "big"))
    s.sendall(header + mask + bytes(c ^ mask[i % 4] for i, c in enumerate(payload)))


while True:
    opcode, payload = read_message()
    if opcode == 1 and json.loads(payload).get("op") == "advertise":
        channels = json.loads(payload)["channels"]
        break
send_text(json.dumps({"op": "subscribe", "subscriptions": [{"id": i, "channelId": c["id"]} for i, c in enumerate(channels)]}))
print(f"subscribed {len(channels)} channels", flush=True)
time.sleep(seconds)  # reads nothing: fusedetd must drop it, the test watches its status
