#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Independent peers for the candump logs fusedet writes (shares no code with the driver).

1. python-can (Debian python3-can) reads the log with can.CanutilsLogReader.
2. can-utils' log2asc converts the same log; its ASC lines are parsed here.
   Both must give the same frames (id, length, data, relative time).
3. A CANopen decoder written here from CiA 301/402 (not from fusedet's code) reads the frames:
   NMT, SDO configuration, heartbeat, SYNC, TPDO1 (position actual + statusword). The tilt
   angles it computes must equal the TiltSamples fusedet printed (--json), and the motion must
   be the commanded nodding: between min and max, N sweeps.

usage: tilt_candump_peer.py FUSEDET WORKDIR SWEEPS
"""
import json
import math
import subprocess
import sys

import can

fusedet, work, sweeps = sys.argv[1], sys.argv[2], int(sys.argv[3])
log = f"{work}/nod.log"
NODE, CPR, GEAR, MIN_DEG, MAX_DEG = 5, 4096, 50.0, -30.0, 30.0  # config/fusedet.yaml defaults

out = subprocess.run([fusedet, "tilt", "simulate", "--sweeps", str(sweeps), "--candump", log, "--json"],
                     check=True, capture_output=True, text=True)
samples = [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]
print(out.stderr.strip())

# 1. python-can
msgs = list(can.CanutilsLogReader(log))
assert msgs, "python-can read no frames"

# 2. log2asc
asc = subprocess.run(["log2asc", "-I", log, "can0"], check=True, capture_output=True, text=True).stdout
rows = []
for line in asc.splitlines():
    parts = line.split()
    # "   0.000000 1  605             Rx   d 8 40 00 10 00 00 00 00 00"
    if len(parts) >= 6 and parts[1] == "1" and parts[3] == "Rx" and parts[4] == "d":
        t, ident, dlc = float(parts[0]), int(parts[2].rstrip("x"), 16), int(parts[5])
        rows.append((t, ident, bytes(int(b, 16) for b in parts[6:6 + dlc])))
assert len(rows) == len(msgs), f"log2asc gave {len(rows)} frames, python-can {len(msgs)}"
t0 = msgs[0].timestamp
for i, (m, (t, ident, data)) in enumerate(zip(msgs, rows)):
    assert m.arbitration_id == ident and bytes(m.data) == data, f"frame {i}: python-can {m} vs log2asc {ident:X} {data.hex()}"
    assert abs((m.timestamp - t0) - t) < 2e-6, f"frame {i}: time {m.timestamp - t0} vs {t}"
print(f"python-can and log2asc agree on {len(msgs)} frames")

# 3. CANopen decoding
nmt, sdo_writes, hb_states, syncs, angles = [], {}, [], 0, []
for m in msgs:
    i, d = m.arbitration_id, bytes(m.data)
    if i == 0x000:
        nmt.append((d[0], d[1]))
    elif i == 0x080:
        syncs += 1
    elif i == 0x600 + NODE and d[0] in (0x23, 0x27, 0x2B, 0x2F):
        n = 4 - ((d[0] >> 2) & 3)
        sdo_writes[(int.from_bytes(d[1:3], "little"), d[3])] = int.from_bytes(d[4:4 + n], "little")
    elif i == 0x700 + NODE:
        hb_states.append(d[0])
    elif i == 0x180 + NODE:
        counts = int.from_bytes(d[0:4], "little", signed=True)
        status = int.from_bytes(d[4:6], "little")
        angles.append((m.timestamp, counts * 2 * math.pi / (CPR * GEAR), status))
assert nmt[0] == (0x81, NODE), f"first NMT must reset node {NODE}: {nmt}"
assert (0x01, NODE) in nmt, "no NMT start"
assert hb_states[0] == 0x00, "first heartbeat must be the boot-up"
assert 0x05 in hb_states, "node never reported operational"
assert sdo_writes[(0x1017, 0)] == 100, "heartbeat producer time"
assert sdo_writes[(0x1A00, 1)] == 0x60640020 and sdo_writes[(0x1A00, 2)] == 0x60410010, "TPDO1 mapping"
assert sdo_writes[(0x1800, 2)] == 1, "TPDO1 on every SYNC"
assert sdo_writes[(0x6060, 0)] == 1, "profile position mode"
speed = sdo_writes[(0x6081, 0)] * 2 * math.pi / (CPR * GEAR)
assert abs(math.degrees(speed) - 15.0) < 0.01, f"profile velocity {math.degrees(speed)} deg/s"

# The driver's samples are exactly our TPDO decoding.
assert len(samples) == len(angles), f"fusedet printed {len(samples)} samples, the log has {len(angles)} TPDOs"
for s, (t, a, _) in zip(samples, angles):
    assert abs(s["stamp"] - t) < 2e-6, (s, t)
    assert abs(s["angle_deg"] - math.degrees(a)) < 1e-4, (s, math.degrees(a))

# The motion: between the limits, direction reversals at the ends = sweeps.
degs = [math.degrees(a) for _, a, _ in angles]
assert min(degs) > MIN_DEG - 0.01 and max(degs) < MAX_DEG + 0.01, (min(degs), max(degs))
ends = 0
last_end = None
for x in degs:
    end = "max" if abs(x - MAX_DEG) < 0.01 else "min" if abs(x - MIN_DEG) < 0.01 else None
    if end and end != last_end:
        ends += 1
        last_end = end
assert ends - 1 >= sweeps, f"{ends - 1} sweeps between the ends, wanted {sweeps}"
ready = [st for _, _, st in angles if (st & 0x6F) == 0x27]
print(f"peer decoded: {len(nmt)} NMT, {len(sdo_writes)} SDO objects written, {len(hb_states)} heartbeats, "
      f"{syncs} SYNC, {len(angles)} TPDO1 ({len(ready)} in operation enabled), {ends - 1} sweeps "
      f"{min(degs):.3f}..{max(degs):.3f} deg, all {len(samples)} fusedet samples equal")
