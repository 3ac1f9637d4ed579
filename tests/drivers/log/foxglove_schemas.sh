#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs @foxglove/schemas, ajv, @mcap/core and fzstd from npm into CACHE once. Validates every
# message of the sample log (every channel kind, a detection box, an MJPEG frame) against
# Foxglove's published schemas; synthesises a log (fusedet synth-log; from KITTI when DATA/kitti
# exists, else the procedural scene), derives its viewer channels with the bundled models
# (fusedet log derive) and checks them the same way plus what a viewer needs, and the tracks
# channels against the tracks lines fusedet replay writes for the raw log (foxglove_schemas.cjs). Compares the
# per-topic counts @mcap/core read with fusedet's own reader (log info) and the scans / tilt
# samples the derive decoded with what synth-log wrote.
# Usage: foxglove_schemas.sh FUSEDET SAMPLE_LOG_WRITER MODELS_DIR DATA CACHE WORKDIR
set -euo pipefail
fusedet=$1 writer=$2 models=$3 data=$4 cache=$5 work=$6
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$cache" "$work"
cache=$(cd "$cache" && pwd) work=$(cd "$work" && pwd)
echo "$("$here/../../npm_tools.sh" "$cache" @foxglove/schemas ajv @mcap/core fzstd), node $(node --version)"
"$writer" "$work/sample.mcap" > /dev/null
node "$here/foxglove_schemas.cjs" "$cache" "$work/sample.mcap" --schemas-only | grep -v '^count '
scene=(--procedural --frames 2)
[[ -d $data/kitti/velodyne ]] && scene=(--kitti "$data/kitti" --frames 8)
"$fusedet" synth-log "${scene[@]}" --out "$work/raw.mcap" | tee "$work/synth.txt"
"$fusedet" log derive "$work/raw.mcap" "$work/view.mcap" --models "$models"
# the tracks the socket would send for the same log, to compare /tracks and /tracks/scene with
printf 'version: 1\ndetection:\n  models: [%s]\n' "$(ls "$models"/*.json | paste -sd, -)" > "$work/replay.yaml"
"$fusedet" replay "$work/raw.mcap" --config "$work/replay.yaml" --out "$work/detections.ndjson" --tracks "$work/tracks.ndjson"
node "$here/foxglove_schemas.cjs" "$cache" "$work/view.mcap" --tracks "$work/tracks.ndjson" | tee "$work/node.txt"
# @mcap/core's counts = fusedet log info's counts, topic by topic.
"$fusedet" log info "$work/view.mcap" | awk '$1 ~ /^\// {print "count", $1, $3}' | sort > "$work/ours.txt"
grep '^count ' "$work/node.txt" | sort > "$work/theirs.txt"
diff "$work/ours.txt" "$work/theirs.txt" && echo "counts agree with fusedet log info: $(wc -l < "$work/ours.txt") topics"
# every synthesised scan decoded again; one tilt sample per TPDO1 the motor simulator sent
scans=$(sed -n 's/^laser *\([0-9]*\) scans.*/\1/p' "$work/synth.txt")
tpdos=$(sed -n 's/.* \([0-9]*\) TPDO1).*/\1/p' "$work/synth.txt")
[[ $(awk '$2 == "/lms291/scan" {print $3}' "$work/theirs.txt") == "$scans" ]] && echo "scans agree: $scans"
[[ $(awk '$2 == "/tilt/sample" {print $3}' "$work/theirs.txt") == "$tpdos" ]] && echo "tilt samples agree: $tpdos"
# with KITTI (8 frames of drive 0005: cars and the cyclist), tracks are confirmed (detected in 2
# of 3 stacks) and one coasts (missed in a stack): every state is drawn
if [[ -d $data/kitti/velodyne ]]; then
  grep -q 'tracks agree with fusedet replay: 8 stacks, [1-9][0-9]* track ids, [1-9][0-9]* confirmed, [1-9][0-9]* coasting, [1-9][0-9]* tentative' \
    "$work/node.txt" && echo "confirmed tracks drawn"
else
  echo "confirmed tracks drawn (procedural scene: not required)"
fi
