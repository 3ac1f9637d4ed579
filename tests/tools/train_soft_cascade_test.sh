#!/usr/bin/env bash
# `fusedet train --soft-cascade` end to end on a small synthetic data set: the model file says
# "cascade": "soft" (format version 3) and its training record, `fusedet eval` runs it on the
# scenes; --soft-start-weights uniform is recorded, an unknown value refused; a hard training of the same data has no "cascade" field;
# --soft-cascade with a validation part is refused clearly.
#   train_soft_cascade_test.sh FUSEDET WRITER WORKDIR
set -euo pipefail
fusedet=$1 writer=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
"$writer" ds 9
train=(train --data ds --class car --layers intensity --grid 6 --window-height 12 --min-height 20
       --scale-factor 1.25 --stages 3 --rounds 12 --negatives 300 --seed 5 --threads 1 --split 1 --progress log)
fail() { echo "FAIL: $*" >&2; exit 1; }
"$fusedet" "${train[@]}" --soft-cascade --out soft.json >out.txt 2>err.txt || { cat err.txt >&2; fail "train failed"; }
grep -q '"version": 3,' soft.json || fail "soft model is not format version 3"
grep -q '"cascade": "soft",' soft.json || fail "soft model lacks \"cascade\": \"soft\""
grep -q '"cascade":"soft, start weights margin"' soft.json || fail "soft model lacks the training record"
"$fusedet" "${train[@]}" --soft-cascade --soft-start-weights uniform --out uniform.json >/dev/null 2>&1 || fail "uniform training failed"
grep -q '"cascade":"soft, start weights uniform"' uniform.json || fail "uniform model lacks its training record"
if "$fusedet" "${train[@]}" --soft-cascade --soft-start-weights exp --out bad.json >bad.out 2>bad.err; then fail "--soft-start-weights exp accepted"; fi
"$fusedet" "${train[@]}" --out hard.json >/dev/null 2>&1 || fail "hard training failed"
if grep -q '"cascade"' hard.json; then fail "hard model names a cascade kind"; fi
grep -q '"version": 1,' hard.json || fail "hard model is not version 1"
"$fusedet" eval -m soft.json --data ds --split all --step 1 --min-neighbors 1 --json >eval.json || fail "eval of the soft model failed"
grep -q '"stacks": 9,' eval.json || { cat eval.json >&2; fail "eval did not run the soft model on the 9 stacks"; }
if "$fusedet" "${train[@]}" --soft-cascade --validation-part 3 --out bad.json >bad.out 2>bad.err; then fail "soft + validation part accepted"; fi
grep -q 'a soft cascade cannot be trained with a validation part' bad.err || { cat bad.err >&2; fail "unclear error"; }
echo "ok"
