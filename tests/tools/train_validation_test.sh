#!/usr/bin/env bash
# `fusedet train --validation-part` end to end on a small synthetic data set (one group, so every
# 3rd item is held back): the start line names the held-back part, the stop line the F per stage
# count and the stages kept, the model carries min_height (the scenes' cars are 24 px high) and
# the validation record; a part of 1 is refused with a clear error.
#   train_validation_test.sh FUSEDET WRITER WORKDIR
set -euo pipefail
fusedet=$1 writer=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
"$writer" ds 9
train=(train --data ds --class car --layers intensity --grid 6 --window-height 12 --min-height 20
       --scale-factor 1.25 --stages 3 --rounds 12 --negatives 300 --seed 5 --threads 1 --split 1 --progress log
       --eval-step 1 --eval-min-neighbors 1)
fail() { echo "FAIL: $*" >&2; exit 1; }
"$fusedet" "${train[@]}" --validation-part 3 --min-height-from-positives --out car.json >out.txt 2>err.txt || { cat err.txt >&2; fail "train failed"; }
cat out.txt err.txt
grep -q 'validation part: 3 held-back items' out.txt err.txt || fail "no validation part in the start line"
grep -q 'validation F by stage count' out.txt || fail "no F per stage count in the stop line"
grep -Eq 'kept [0-9]+ of [0-9]+ stages' out.txt || fail "no kept stage count"
grep -q '"min_height": 24,' car.json || fail "model lacks min_height 24"
grep -q '"validation_part":"1/3: 3 items' car.json || fail "model lacks the validation record"
if "$fusedet" "${train[@]}" --validation-part 1 --out bad.json >bad.out 2>bad.err; then fail "--validation-part 1 accepted"; fi
grep -q 'validation part: 1/n of the items, n >= 2' bad.err || { cat bad.err >&2; fail "unclear error for part 1"; }
echo "ok"
