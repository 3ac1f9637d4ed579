#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet experiments --stage-sweep` on the quick run's cached fold models (no training): the
# sweep point with every stage and the run's min neighbours must give exactly the `all` row's
# hits / false alarms / misses (the cut is the identity there), a 1-stage cut must change them,
# the report and results.json carry the sweep, and --class-stages rejects malformed input.
#   experiments_sweep_test.sh FUSEDET DATA QUICK_OUT WORKDIR
set -euo pipefail
fusedet=$1 data=$2 quick=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
"$fusedet" experiments --quick --data "$data" --dataset-cache "$quick/dataset" --model-cache "$quick/fold-models" \
  --classes car --configs all --no-peers --stage-sweep 1,4 --neighbors-sweep 3 --out "$work/out" >"$work/out.txt" \
  || { cat "$work/out.txt" >&2; fail "experiments failed"; }
cat "$work/out.txt"
grep -q '3 cached folds' "$work/out.txt" || fail "fold models were not all taken from the quick run's cache"
counts() { sed -nE 's/.*\(([0-9]+) hits, ([0-9]+) false alarms, ([0-9]+) misses.*/\1 \2 \3/p'; }
all=$(grep -E '^car +all +F' "$work/out.txt" | counts)
four=$(grep -E '^car +sweep: +4 stages, min neighbours 3 ' "$work/out.txt" | counts)
one=$(grep -E '^car +sweep: +1 stages, min neighbours 3 ' "$work/out.txt" | counts)
[ -n "$all" ] && [ -n "$four" ] && [ -n "$one" ] || fail "missing result lines"
[ "$all" = "$four" ] || fail "all stages kept ($four) differs from the all row ($all)"
[ "$one" != "$four" ] || fail "cutting to 1 stage changed nothing ($one)"
grep -q '## Stage count and grouping sweep' "$work/out/report.md" || fail "no sweep section in report.md"
grep -q '"stage_sweep"' "$work/out/results.json" || fail "no stage_sweep in results.json"
# The miss analysis explains exactly the `all` row's misses.
misses=$(echo "$all" | cut -d' ' -f3)
grep -q "^### car / all: $misses of [0-9]* positives missed" "$work/out/report.md" \
  || { grep '^### car' "$work/out/report.md" >&2; fail "miss analysis does not count the all row's $misses misses"; }
grep -q '"miss_analysis"' "$work/out/results.json" || fail "no miss_analysis in results.json"
rc=0
"$fusedet" experiments --data "$data" --out "$work/bad" --class-stages person >"$work/bad.txt" 2>&1 || rc=$?
[ "$rc" -eq 1 ] || { cat "$work/bad.txt" >&2; fail "--class-stages person: exit status $rc, expected 1 (an error, no crash)"; }
grep -q 'expected CLASS=N with N >= 1' "$work/bad.txt" || { cat "$work/bad.txt" >&2; fail "unclear --class-stages error"; }
rc=0
"$fusedet" experiments --data "$data" --out "$work/bad" --classes car --class-stages bike=3 >"$work/bad.txt" 2>&1 || rc=$?
[ "$rc" -eq 1 ] && grep -q "class 'bike' is not among --classes" "$work/bad.txt" || { cat "$work/bad.txt" >&2; fail "--class-stages for a class not run"; }
echo "ok"
