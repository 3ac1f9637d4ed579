#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet autolabel` as a user runs it: Yolo-Fastest-XL (../shared/models) teaches an imported KITTI
# folder; its labels are marked teacher (CVAT source="auto" on export), human labels stay, a second run
# gives the same labels, --replace-human leaves only the teacher's, bad options are refused.
#   autolabel_test.sh FUSEDET DATA_DIR NETWORKS_DIR WORKDIR
set -euo pipefail
fusedet=$1 data=$2 models=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
ds=$work/ds
teacher=(--kind darknet --model "$models/yolo-fastest-1.1-xl.cfg" --model "$models/yolo-fastest-1.1-xl.weights" --input 832x256)
"$fusedet" import-kitti --root "$data/kitti" --out "$ds" --quiet
"$fusedet" dataset export "$ds" --format coco --out "$work/human.json"
humans=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["annotations"]))' "$work/human.json")

"$fusedet" autolabel "$ds" "${teacher[@]}" -q | tee "$work/run1.txt"
read -r taught uncertain < <(sed -n 's/^autolabel [0-9]* items: \([0-9]*\) teacher labels, \([0-9]*\) ignore regions.*/\1 \2/p' "$work/run1.txt")
[ "${taught:-0}" -gt 0 ] || fail "the teacher labelled nothing"
"$fusedet" dataset export "$ds" --format cvat --out "$work/taught.xml"
auto=$(grep -c 'source="auto"' "$work/taught.xml")
manual=$(grep -c 'source="manual"' "$work/taught.xml")
[ "$auto" -eq $((taught + uncertain)) ] || fail "$auto boxes marked auto, the run reported $taught + $uncertain"
[ "$manual" -eq "$humans" ] || fail "$manual human boxes after teaching, $humans before"
echo "teacher: $taught labels + $uncertain ignore regions marked auto, $manual human labels kept"

"$fusedet" autolabel "$ds" "${teacher[@]}" -q > "$work/run2.txt"
"$fusedet" dataset export "$ds" --format cvat --out "$work/taught2.xml"
cmp -s "$work/taught.xml" "$work/taught2.xml" || fail "a second run changed the labels"

"$fusedet" autolabel "$ds" "${teacher[@]}" -q --replace-human | tee "$work/run3.txt"
"$fusedet" dataset export "$ds" --format cvat --out "$work/only.xml"
[ "$(grep -c 'source="manual"' "$work/only.xml" || true)" -eq 0 ] || fail "--replace-human kept human labels"
[ "$(grep -c 'source="auto"' "$work/only.xml")" -gt "$auto" ] || fail "--replace-human taught no box that a human label had covered"

rc=0; "$fusedet" autolabel "$ds" "${teacher[@]}" --classes truck 2> "$work/err.txt" || rc=$?
[ $rc -eq 1 ] && grep -qF "'truck' is no class the COCO teacher knows" "$work/err.txt" || fail "--classes truck not refused"
rc=0; "$fusedet" autolabel "$ds" --kind darknet --model "$models/yolo-fastest-1.1-xl.cfg" --input 832x256 2> "$work/err.txt" || rc=$?
cat "$work/err.txt"
[ $rc -eq 1 ] || fail "a darknet teacher without weights not refused (exit $rc)"
echo "autolabel_test: PASS"
