#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet compare` as a user runs it.
#   compare_test.sh FUSEDET WORKDIR             hand-written outcomes files: the table, --json, refusals
#   compare_test.sh FUSEDET WORKDIR QUICK_OUT   the quick experiments run against itself: F and AP equal
#                                               its results.json, the difference is exactly 0
# The hand-written files are the worked example of tests/boost/eval/paired_comparison_test.cpp: two
# frames with one car each; A hits both (F 1, AP 1), B has a false alarm above its one hit (F 0.5,
# AP 20 x 0.5 / 40 = 0.25).
set -euo pipefail
fusedet=$1 work=$2 quick=${3:-}
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
expect_error() {  # expect_error PATTERN ARGS...: exit status 1 and the pattern in the error
  local pattern=$1 rc=0
  shift
  "$fusedet" compare "$@" >"$work/err.txt" 2>&1 || rc=$?
  cat "$work/err.txt"
  [ "$rc" -eq 1 ] || fail "compare $*: exit status $rc, expected 1"
  grep -qF -- "$pattern" "$work/err.txt" || fail "compare $*: no '$pattern' in the error"
}

if [ -n "$quick" ]; then
  "$fusedet" compare "$quick" "$quick" --class car --config all >"$work/self.txt" || fail "compare failed"
  cat "$work/self.txt"
  python3 - "$quick/results.json" "$work/self.txt" <<'EOF' || fail "compare disagrees with results.json"
import json, re, sys
results = json.load(open(sys.argv[1]))
row = next(r for r in results["results"] if r["class"] == "car" and r["config"] == "all")
line = next(l for l in open(sys.argv[2]) if l.startswith("car "))
cols = line.split()
assert cols[1] == "3fold" and cols[2] == "all", cols
f, ap = row["f_measure"]["value"], row["average_precision"]["value"]
assert cols[4] == cols[5] == "%.3f" % f, (cols, f)
assert "+0.000 [+0.000, +0.000]   not shown" in line, line
assert "%.3f  %.3f" % (ap, ap) in line, (line, ap)
print("ok: F %.3f, AP %.3f as results.json" % (f, ap))
EOF
  # Learning-curve points are in outcomes.json too and pair within one run (--config-b).
  "$fusedet" compare "$quick" "$quick" --class car --config all:positives=all --config-b all:positives=16 \
    >"$work/curve.txt" || fail "compare of two learning-curve points failed"
  cat "$work/curve.txt"
  grep -qE '^car +3fold +all:positives=all/all:positives=16 +104 ' "$work/curve.txt" || fail "learning-curve pair row"
  exit 0
fi

rule='{"min_iou":0.7,"min_height":25,"max_occlusion":1,"max_truncation":0.3,"min_detection_height":25,"alias_classes":[],"neighbour_classes":["van","Van"],"ignore_classes":[],"false_alarm_classes":["Truck","Tram","Misc","Person_sitting"]}'
write() {  # write FILE RULE DETECTIONS_OF_FRAME_0 DETECTIONS_OF_FRAME_1
  cat >"$1" <<EOF
{"format": "fusedet-outcomes", "version": 1, "command": "hand-written $1",
 "sets": [{"class": "car", "protocol": "lodo", "folds": 2, "config": "all", "rule": $2,
   "frames": [{"id": "d1/000001", "positives": 1, "detections": $3},
              {"id": "d2/000002", "positives": 1, "detections": $4}]}]}
EOF
}
write "$work/a.json" "$rule" '[[2, 1]]' '[[1, 1]]'
write "$work/b.json" "$rule" '[[2, 0]]' '[[1, 1]]'
"$fusedet" compare "$work/a.json" "$work/b.json" >"$work/ab.txt" || fail "compare a b failed"
cat "$work/ab.txt"
grep -qE '^car +lodo +all +2 +1\.000 +0\.500 +\+0\.500 \[\+0\.000, \+1\.000\] +not shown +1\.000 +0\.250 +\+0\.750 \[' "$work/ab.txt" \
  || fail "table line of a against b"
grep -qE '^compare: car lodo all: F \+0\.500 \[\+0\.000, \+1\.000\] not shown; AP \+0\.750 ' "$work/ab.txt" \
  || fail "compare: summary line"
tail -n1 "$work/ab.txt" | grep -q '^compare: ' || fail "the output does not end with compare: lines"
"$fusedet" compare "$work/a.json" "$work/a.json" >"$work/aa.txt"
grep -qE '^car +lodo +all +2 +1\.000 +1\.000 +\+0\.000 \[\+0\.000, \+0\.000\] +not shown ' "$work/aa.txt" \
  || fail "identical runs: expected +0.000 [+0.000, +0.000] not shown"
"$fusedet" compare "$work/a.json" "$work/b.json" --json --bootstrap 200 >"$work/ab.json"
python3 - "$work/ab.json" <<'EOF' || fail "--json"
import json, sys
j = json.load(open(sys.argv[1]))
r = j["rows"][0]
assert (r["class"], r["protocol"], r["config"], r["frames"]) == ("car", "lodo", "all", 2), r
assert r["f_measure"]["a"] == 1 and r["f_measure"]["b"] == 0.5 and r["f_measure"]["verdict"] == "not shown", r
assert r["average_precision"]["difference"] == 0.75, r
assert r["counts_b"] == {"hits": 1, "false_alarms": 1, "misses": 1, "positives": 2}, r
assert j["bootstrap"]["resamples"] == 200 and r["f_measure"]["interval"]["resamples"] == 200, j
EOF

# --protocol-b: a's lodo set against b's 3fold set of the same frames (e.g. the learning curve's
# point on all training frames of 3 folds: less training data per fold).
sed 's|"protocol": "lodo", "folds": 2|"protocol": "3fold", "folds": 3|' "$work/b.json" >"$work/b3.json"
expect_error "no class / protocol / configuration matching protocol lodo is in both runs" \
  "$work/a.json" "$work/b3.json" --protocol lodo
"$fusedet" compare "$work/a.json" "$work/b3.json" --protocol lodo --protocol-b 3fold >"$work/ab3.txt" \
  || fail "compare --protocol-b failed"
cat "$work/ab3.txt"
grep -qE '^car +lodo/3fold +all +2 +1\.000 +0\.500 +\+0\.500 \[\+0\.000, \+1\.000\] +not shown ' "$work/ab3.txt" \
  || fail "table line of --protocol-b"
grep -qE '^compare: car lodo/3fold all: F \+0\.500 ' "$work/ab3.txt" || fail "compare: line of --protocol-b"
expect_error "a protocol of the second run (3fold) needs the first run's protocol to pair it with" \
  "$work/a.json" "$work/b3.json" --protocol-b 3fold

# Refusals: another IoU rule (--min-iou 0.5 against the devkit's 0.7), other frames, no common set,
# truncated and missing files.
write "$work/pascal.json" "${rule/0.7/0.5}" '[[2, 1]]' '[[1, 1]]'
expect_error "the runs match detections by different rules (hit overlap (IoU) 0.5 against 0.7)" \
  "$work/pascal.json" "$work/a.json"
sed 's|d2/000002|d3/000003|' "$work/a.json" >"$work/other.json"
expect_error "the runs tested different frames (2 against 2; 1 only in the first: d2/000002; 1 only in the second: d3/000003)" \
  "$work/a.json" "$work/other.json"
expect_error "no class / protocol / configuration matching class person is in both runs" \
  "$work/a.json" "$work/b.json" --class person
head -c 150 "$work/a.json" >"$work/cut.json"
expect_error "cut.json: line 2, column " "$work/a.json" "$work/cut.json"
mkdir -p "$work/empty-run"
expect_error "empty-run/outcomes.json: cannot open (no such file" "$work/empty-run" "$work/a.json"
"$fusedet" compare --help >"$work/help.txt"
grep -q "paired bootstrap" "$work/help.txt" && grep -q "Examples:" "$work/help.txt" || fail "--help"
echo "ok"
