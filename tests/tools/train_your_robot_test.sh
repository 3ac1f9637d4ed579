#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# docs/train-your-robot.md as a test: every ```sh block of the page, in order, in an empty folder
# (so the page cannot drift from what runs), then checks on what the steps left behind.
#   train_your_robot_test.sh PAGE FUSEDET_DIR DATA_DIR NETWORKS_DIR WORKDIR
set -euo pipefail
page=$1 bin=$2 data=$3 models=$4 work=$5
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
awk '/^```sh$/{on=1; next} /^```/{on=0} on' "$page" > "$work/page.sh"
[ "$(grep -c . "$work/page.sh")" -ge 10 ] || fail "the page has almost no sh commands"
echo "--- the page's commands:"; cat "$work/page.sh"; echo "---"
(cd "$work" && PATH="$bin:$PATH" FUSEDET_DATA="$data" MODELS="$models" bash -euo pipefail page.sh) || fail "a command of the page failed"

cd "$work"
python3 - <<'PY' || fail "the steps did not leave what the page says"
import json, os
items = json.load(open("robot/dataset.json"))["items"]
assert len(items) == 16, len(items)
labels = [l for m in items for l in json.load(open(f"robot/items/{m['id']}/item.json"))["labels"]]
assert any(l["origin"] == "teacher" and l["class"] == "car" and not l["ignore"] for l in labels), "no teacher car"
assert all(os.path.exists(f"robot/images/{m['id']}.png") for m in items), "an image for labelling is missing"
model = json.load(open("car.json"))
assert model["class"] == "car" and model["stages"], "car.json is no car cascade"
stacks = [json.loads(l) for l in open("detections.ndjson") if '"type":"detections"' in l]
assert len(stacks) == 16, f"the deployed model saw {len(stacks)} stacks"
print(f"train_your_robot: {len(items)} items, {sum(l['origin'] == 'teacher' for l in labels)} teacher labels, "
      f"car.json with {len(model['stages'])} stages, {sum(len(s['detections']) for s in stacks)} detections on 16 stacks")
PY
[ -s review.png ] || fail "no review picture"
echo "train_your_robot_test: PASS"
