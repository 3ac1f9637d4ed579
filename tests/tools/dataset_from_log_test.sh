#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet dataset from-log` as a user runs it on a log synthesised from KITTI frames: one item per
# stack `fusedet replay` fuses (frame stamps equal), --every, camera images named as the labelling
# files name them (a teacher's CVAT export names only images that exist), a cut log refused by name.
#   dataset_from_log_test.sh FUSEDET DATA_DIR NETWORKS_DIR DEMO_CONFIG WORKDIR
set -euo pipefail
fusedet=$1 data=$2 models=$3 config=$4 work=$5
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
log=$work/drive.mcap
"$fusedet" synth-log --kitti "$data/kitti" --frames 4 --out "$log" > /dev/null
"$fusedet" replay "$log" --config "$config" --out "$work/replay.ndjson"
"$fusedet" dataset from-log "$log" --out "$work/ds" | tee "$work/out.txt"
# The stacks replay sent and the items from-log wrote: same count, same camera frame stamps.
python3 - "$work/replay.ndjson" "$work/ds" <<'PY' || fail "from-log's items are not replay's stacks"
import json, os, sys
stacks = [json.loads(l) for l in open(sys.argv[1]) if '"type":"detections"' in l]
manifest = json.load(open(os.path.join(sys.argv[2], "dataset.json")))["items"]
assert len(stacks) >= 3 and len(manifest) == len(stacks), (len(stacks), len(manifest))
items = [json.load(open(os.path.join(sys.argv[2], "items", m["id"], "item.json"))) for m in manifest]
assert [i["stamp_ns"] for i in items] == [s["frame_ns"] for s in stacks], "frame stamps differ"
assert [i["stack_id"] for i in items] == [s["stack"] for s in stacks], "stack ids differ"
names = {l["name"] for l in items[0]["layers"]}
assert {"red", "green", "blue", "intensity", "hue", "distance", "remission"} <= names, names
assert all(i["labels"] == [] and i["group"] == "drive" for i in items)
print(f"from-log: {len(items)} items = replay's {len(stacks)} stacks, stamps and ids equal")
PY
n=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["items"]))' "$work/ds/dataset.json")
"$fusedet" dataset from-log "$log" --out "$work/every2" --every 2 --no-images
m=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["items"]))' "$work/every2/dataset.json")
[ "$m" -eq $(((n + 1) / 2)) ] || fail "--every 2 kept $m of $n"
[ ! -e "$work/every2/images" ] || fail "--no-images wrote images"

# Label the images: the teacher's labels exported as CVAT name images that from-log wrote.
"$fusedet" autolabel "$work/ds" --kind darknet --model "$models/yolo-fastest-1.1-xl.cfg" \
  --model "$models/yolo-fastest-1.1-xl.weights" --input 832x256 -q
"$fusedet" dataset export "$work/ds" --format cvat --out "$work/labels.xml"
images=0
for name in $(sed -n 's/.*<image id="[0-9]*" name="\([^"]*\)".*/\1/p' "$work/labels.xml"); do
  [ -f "$work/ds/images/$name" ] || fail "CVAT names $name, which from-log did not write"
  images=$((images + 1))
done
[ "$images" -eq "$n" ] || fail "$images images in the CVAT file, $n items"

# A log cut short: refused or read to its last complete chunk, never a crash.
head -c 20000 "$log" > "$work/cut.mcap"
rc=0; "$fusedet" dataset from-log "$work/cut.mcap" --out "$work/cut" > "$work/cut.txt" 2>&1 || rc=$?
cat "$work/cut.txt"
[ $rc -eq 1 ] || [ $rc -eq 3 ] || fail "a cut log gave exit $rc"
grep -qF "cut.mcap" "$work/cut.txt" || fail "the cut log's message does not name it"
echo "dataset_from_log_test: PASS"
