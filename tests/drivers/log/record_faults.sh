#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet record` (against lms291-sim on a pty) under two faults, issue 37's fault matrix:
#  - disk full: the file may not grow past 48 KiB (~7 s of LMS data; RLIMIT_FSIZE: the kernel refuses the write past
#    it with EFBIG through the same write path a full disk refuses with ENOSPC; SIGXFSZ ignored as
#    a daemon would). Recording must stop at once with an error naming the file, exit 1, and the
#    file so far must read back (`fusedet log info`: its complete chunks, cut after them).
#  - SIGKILL mid-recording: the file so far must read back the same way, losing at most the last
#    second (a chunk is closed every second).
# Usage: record_faults.sh FUSEDET LMS291_SIM. Prints one line per fault with what it measured.
set -euo pipefail
fusedet=$1 sim=$2
d=$(mktemp -d)
trap 'kill $simpid 2> /dev/null; wait 2> /dev/null; rm -rf "$d"' EXIT
"$sim" --link "$d/tty" --duration 120 > "$d/sim.log" 2>&1 &
simpid=$!
for _ in $(seq 200); do [[ -e $d/tty ]] && break; sleep 0.1; done
[[ -e $d/tty ]] || { echo "lms291-sim made no pty in 20 s:"; cat "$d/sim.log"; exit 1; }
printf 'laser:\n  device: %s\n  baud: 500000\ncamera:\n  device: %s\n' "$d/tty" "$d/novideo" > "$d/c.yaml"

now_ms() { date +%s%3N; }
size_of() { stat -c %s "$1" 2> /dev/null || echo 0; }
fail() { echo "record_faults: $*"; exit 1; }

# --- disk full -------------------------------------------------------------------------------
limit=$((48 * 1024))
t0=$(now_ms)
(trap '' XFSZ; ulimit -f $((limit / 1024)); exec "$fusedet" record --config "$d/c.yaml" --out "$d/full.mcap" --no-can --duration 60) \
  > "$d/full.out" 2> "$d/full.err" &
rec=$!
# When did the file reach its final size? Sampled every 20 ms until the recorder exits.
last=0 grew_ms=$t0
while kill -0 $rec 2> /dev/null; do
  s=$(size_of "$d/full.mcap")
  if ((s != last)); then last=$s grew_ms=$(now_ms); fi
  sleep 0.02
done
set +e
wait $rec
rc=$?
set -e
end_ms=$(now_ms)
size=$(size_of "$d/full.mcap")
((rc == 1)) || { cat "$d/full.err"; fail "disk full: exit $rc, expected 1"; }
grep -q "full.mcap.*File too large" "$d/full.err" || { cat "$d/full.err"; fail "disk full: no error naming the file and the cause"; }
((size <= limit)) || fail "disk full: file of $size bytes past the $limit limit"
((end_ms - t0 < 30000)) || fail "disk full: recording went on for $((end_ms - t0)) ms"
set +e
"$fusedet" log info "$d/full.mcap" > "$d/full.info" 2>&1
info_rc=$?
set -e
((info_rc == 3)) || { cat "$d/full.info"; fail "disk full: log info exit $info_rc, expected 3 (cut)"; }
grep -q "truncated cut at byte" "$d/full.info" || { cat "$d/full.info"; fail "disk full: log info does not say where it was cut"; }
scans=$(sed -n 's|^ */lms291/scan  *foxglove.LaserScan  *\([0-9]*\).*|\1|p' "$d/full.info")
((${scans:-0} > 0)) || { cat "$d/full.info"; fail "disk full: no scan readable in the file so far"; }
echo "record_faults: disk full: recording stopped $((end_ms - grew_ms)) ms after the file stopped growing" \
  "($size of $limit bytes, exit 1: $(grep -o 'error: .*' "$d/full.err" | head -1)); log info reads $scans scans, exit 3 (cut)"

# --- SIGKILL ---------------------------------------------------------------------------------
"$fusedet" record --config "$d/c.yaml" --out "$d/kill.mcap" --no-can --duration 60 > /dev/null 2> "$d/kill.err" &
rec=$!
t0=$(now_ms)
for _ in $(seq 300); do (($(size_of "$d/kill.mcap") > 20000)) && break; sleep 0.05; done
sleep 1.5
kill -KILL $rec
killed_ms=$(now_ms)
wait $rec 2> /dev/null || true
set +e
"$fusedet" log info "$d/kill.mcap" > "$d/kill.info" 2>&1
info_rc=$?
set -e
((info_rc == 3)) || { cat "$d/kill.info"; fail "SIGKILL: log info exit $info_rc, expected 3 (cut)"; }
scans=$(sed -n 's|^ */lms291/scan  *foxglove.LaserScan  *\([0-9]*\).*|\1|p' "$d/kill.info")
((${scans:-0} > 0)) || { cat "$d/kill.info"; fail "SIGKILL: no scan readable in the file so far"; }
# What the file holds against how long the recorder ran: a chunk closes every second, so at most
# that (plus the start-up before the first scan) is lost.
alive_ms=$((killed_ms - t0))
span_ms=$(sed -n 's/^time .*(\([0-9.]*\) s)$/\1/p' "$d/kill.info" | awk '{printf "%d", $1 * 1000}')
((alive_ms - span_ms < 2500)) || { cat "$d/kill.info"; fail "SIGKILL: $alive_ms ms recorded, the file spans only $span_ms ms"; }
echo "record_faults: SIGKILL after $alive_ms ms of recording: log info reads $scans scans spanning $span_ms ms" \
  "(lost $((alive_ms - span_ms)) ms incl. start-up; $(grep -o 'truncated cut at byte [0-9]*' "$d/kill.info")), exit 3"
