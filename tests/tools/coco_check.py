#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# An independent reader of a COCO object-detection file (shares no code with fusedet): checks COCO's
# published field rules and compares every box with the KITTI label_2 text it came from.
#   coco_check.py COCO.json INFO.json KITTI_ROOT...
# INFO.json is `fusedet dataset info --json` of the exported data set (counts must agree); each
# KITTI_ROOT's label_2/<frame>.txt is read here with the KITTI devkit's field order.
import json
import math
import os
import sys


def fail(msg):
    sys.exit("coco_check: FAIL: " + msg)


coco = json.load(open(sys.argv[1]))
info = json.load(open(sys.argv[2]))
roots = sys.argv[3:]

for key in ("images", "annotations", "categories"):
    if not isinstance(coco.get(key), list):
        fail(f"'{key}' is not a list")


def is_int(v):
    return isinstance(v, int) and not isinstance(v, bool)


categories = {}
for c in coco["categories"]:
    if not is_int(c.get("id")) or not isinstance(c.get("name"), str):
        fail(f"category {c}: id must be an integer, name a string")
    if c["id"] in categories or c["name"] in categories.values():
        fail(f"category {c} twice")
    categories[c["id"]] = c["name"]
# COCO's own ids for the classes it shares with the project.
for name, cid in (("person", 1), ("bicycle", 2), ("car", 3)):
    if name in categories.values() and categories.get(cid) != name:
        fail(f"{name} is not COCO's category {cid}")

images = {}
for im in coco["images"]:
    if not is_int(im.get("id")) or im["id"] in images:
        fail(f"image {im}: id missing, not an integer or twice")
    if not isinstance(im.get("file_name"), str) or not is_int(im.get("width")) or not is_int(im.get("height")):
        fail(f"image {im}: file_name, width, height")
    if im["width"] <= 0 or im["height"] <= 0:
        fail(f"image {im}: size")
    images[im["id"]] = im

ids = set()
plain, crowd, per_image = {}, {}, {}
for a in coco["annotations"]:
    if not is_int(a.get("id")) or a["id"] in ids:
        fail(f"annotation {a}: id missing, not an integer or twice")
    ids.add(a["id"])
    if a.get("image_id") not in images:
        fail(f"annotation {a['id']}: image_id names no image")
    if a.get("category_id") not in categories:
        fail(f"annotation {a['id']}: category_id names no category")
    b = a.get("bbox")
    if not isinstance(b, list) or len(b) != 4 or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in b):
        fail(f"annotation {a['id']}: bbox must be 4 finite numbers")
    if b[2] < 0 or b[3] < 0:
        fail(f"annotation {a['id']}: negative width or height")
    if a.get("iscrowd") not in (0, 1):
        fail(f"annotation {a['id']}: iscrowd must be 0 or 1")
    if not math.isclose(a.get("area", -1), b[2] * b[3], rel_tol=1e-9, abs_tol=1e-6):
        fail(f"annotation {a['id']}: area {a.get('area')} is not width x height")
    name = categories[a["category_id"]]
    (crowd if a["iscrowd"] else plain)[name] = (crowd if a["iscrowd"] else plain).get(name, 0) + 1
    per_image.setdefault(a["image_id"], []).append(a)

# Counts against the data set's own report (bike is COCO's bicycle).
expected_plain = {("bicycle" if k == "bike" else k): v for k, v in info["labels"].items()}
if plain != expected_plain:
    fail(f"labels per class {plain} != data set {expected_plain}")
if crowd != info["ignore_regions"]:
    fail(f"crowd regions {crowd} != data set ignore regions {info['ignore_regions']}")
if len(images) != info["items"]:
    fail(f"{len(images)} images != {info['items']} items")

# Every box against the KITTI text it was imported from: (type, x1, y1, x2, y2) per line.
compared = 0
for im in images.values():
    group, frame = os.path.split(os.path.splitext(im["file_name"])[0])
    root = next((r for r in roots if os.path.basename(os.path.normpath(r)) == group), None)
    if root is None:
        fail(f"image {im['file_name']}: no KITTI root named {group}")
    kitti = []
    for line in open(os.path.join(root, "label_2", frame + ".txt")):
        f = line.split()
        if f:
            kitti.append((float(f[4]), float(f[5]), float(f[6]) - float(f[4]), float(f[7]) - float(f[5])))
    got = sorted(tuple(a["bbox"]) for a in per_image.get(im["id"], []))
    if len(got) != len(kitti):
        fail(f"{im['file_name']}: {len(got)} annotations, KITTI has {len(kitti)} objects")
    for g, k in zip(got, sorted(kitti)):
        if any(abs(x - y) > 1e-6 for x, y in zip(g, k)):
            fail(f"{im['file_name']}: box {g} != KITTI {k}")
        compared += 1
print(f"coco_check: OK: {len(images)} images, {len(ids)} annotations ({sum(crowd.values())} crowd), "
      f"{len(categories)} categories, {compared} boxes equal to KITTI's label_2")
