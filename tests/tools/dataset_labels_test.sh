#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet dataset` as a user runs it on two imported KITTI folders: info; export as COCO, checked by
# an independent reader against KITTI's own label text (coco_check.py); labels cleared, then brought
# back from each format (CVAT, KITTI, COCO) with the same counts; split by group and merged back;
# refusals leave the labels as they were.
# Detections of the bundled car model as COCO results: image ids of the export, COCO's car id, as
# many results as eval counted detections.
#   dataset_labels_test.sh FUSEDET DATA_DIR WORKDIR CAR_MODEL
set -euo pipefail
fusedet=$1 data=$2 work=$3 car=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
ds=$work/ds
"$fusedet" import-kitti --root "$data/kitti" --root "$data/kitti_0009" --out "$ds" --quiet
"$fusedet" dataset info "$ds"
"$fusedet" dataset info "$ds" --json > "$work/info0.json"

"$fusedet" dataset export "$ds" --format coco --out "$work/labels.json"
python3 "$here/coco_check.py" "$work/labels.json" "$work/info0.json" "$data/kitti" "$data/kitti_0009"
"$fusedet" eval --model "$car" --data "$ds" --split all --json --coco-results "$work/results.json" > "$work/eval.json"
python3 - "$work/labels.json" "$work/results.json" "$work/eval.json" <<'PY' || fail "COCO results do not fit the export"
import json, math, sys
labels, results, ev = (json.load(open(f)) for f in sys.argv[1:4])
images = {im["id"] for im in labels["images"]}
assert isinstance(results, list) and results, "no results"
for r in results:
    assert set(r) == {"image_id", "category_id", "bbox", "score"}, r
    assert r["image_id"] in images, f"image_id {r['image_id']} is no image of the export"
    assert r["category_id"] == 3, f"car must be COCO category 3: {r}"
    assert len(r["bbox"]) == 4 and all(math.isfinite(v) for v in r["bbox"]) and r["bbox"][2] > 0 and r["bbox"][3] > 0, r
counted = ev["hits"] + ev["false_alarms"] + ev["ignored_detections"]
assert len(results) == counted, f"{len(results)} results, eval counted {counted} detections"
print(f"COCO results: {len(results)} car detections on {len({r['image_id'] for r in results})} export images, as eval counted")
PY
"$fusedet" dataset export "$ds" --format cvat --out "$work/labels.xml"
"$fusedet" dataset export "$ds" --format kitti --out "$work/label_2"

# A COCO file naming every image with no annotation clears the labels.
python3 - "$work/labels.json" "$work/empty.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1])); c["annotations"] = []; json.dump(c, open(sys.argv[2], "w"))
PY
for format in cvat kitti coco; do
  case $format in cvat) file=$work/labels.xml ;; kitti) file=$work/label_2 ;; coco) file=$work/labels.json ;; esac
  "$fusedet" dataset import "$ds" "$work/empty.json" --format coco
  "$fusedet" dataset info "$ds" --json > "$work/cleared.json"
  python3 -c 'import json,sys; i=json.load(open(sys.argv[1])); sys.exit(1 if i["labels"] or i["ignore_regions"] else 0)' \
    "$work/cleared.json" || fail "labels not cleared before $format"
  "$fusedet" dataset import "$ds" "$file" --format $format
  "$fusedet" dataset info "$ds" --json > "$work/info-$format.json"
  cmp -s "$work/info0.json" "$work/info-$format.json" || { diff "$work/info0.json" "$work/info-$format.json"; fail "$format round trip changed the data set"; }
  echo "round trip $format: same items, groups and labels per class"
done

# Refused: an unknown class and a file of another data set's images; nothing changes.
python3 - "$work/labels.json" "$work/unknown.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1])); c["categories"][0]["name"] = "motorcycle"; json.dump(c, open(sys.argv[2], "w"))
PY
rc=0; "$fusedet" dataset import "$ds" "$work/unknown.json" --format coco 2> "$work/err.txt" || rc=$?
cat "$work/err.txt"
[ $rc -eq 1 ] && grep -qF "class 'motorcycle' is not in the class table" "$work/err.txt" || fail "unknown class not refused (exit $rc)"
"$fusedet" dataset info "$ds" --json | cmp -s - "$work/info0.json" || fail "a refused import changed labels"

# Split by group and merged back: the same data set.
"$fusedet" dataset split "$ds" --by log --out "$work/groups"
[ -f "$work/groups/kitti/dataset.json" ] && [ -f "$work/groups/kitti_0009/dataset.json" ] || fail "split wrote no per-group data sets"
"$fusedet" dataset merge "$work/groups/kitti" "$work/groups/kitti_0009" --out "$work/merged"
"$fusedet" dataset info "$work/merged" --json | cmp -s - "$work/info0.json" || fail "split + merge changed the data set"
# By raw drive: kitti and kitti_0009 are KITTI drives 0005 and 0009 (their SOURCE.md headings).
"$fusedet" dataset split "$ds" --by drive --kitti-root "$data" --out "$work/drives"
ls "$work/drives"
[ -f "$work/drives/2011_09_26_drive_0005/dataset.json" ] && [ -f "$work/drives/2011_09_26_drive_0009/dataset.json" ] ||
  fail "split --by drive did not name the raw drives"
rc=0; "$fusedet" dataset merge "$work/groups/kitti" --out "$work/merged" 2> "$work/err.txt" || rc=$?
[ $rc -eq 1 ] && grep -qF "is already in" "$work/err.txt" || fail "merge over existing ids not refused"
echo "dataset_labels_test: PASS"
