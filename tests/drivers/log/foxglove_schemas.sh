#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs @foxglove/schemas, ajv, @mcap/core and fzstd from npm into CACHE once. Validates every
# message of the sample log (every channel kind, a detection box, an MJPEG frame) against
# Foxglove's published schemas; synthesises a log with the derived channels (fusedet synth-log
# --derived with the bundled models; from KITTI when DATA/kitti exists, else the procedural
# scene) and checks it the same way plus what a viewer needs (foxglove_schemas.cjs). Compares the
# per-topic counts @mcap/core read with fusedet's own reader (log info) and the scans / tilt
# samples the derive decoded with what synth-log wrote.
# Usage: foxglove_schemas.sh FUSEDET SAMPLE_LOG_WRITER MODELS_DIR DATA CACHE WORKDIR
set -euo pipefail
fusedet=$1 writer=$2 models=$3 data=$4 cache=$5 work=$6
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$cache" "$work"
cache=$(cd "$cache" && pwd) work=$(cd "$work" && pwd)
packages=(@foxglove/schemas ajv @mcap/core fzstd)
(
  flock 9
  for p in "${packages[@]}"; do
    if [[ ! -f $cache/node_modules/$p/package.json ]]; then
      (cd "$cache" && npm install --prefix "$cache" --no-audit --no-fund --silent "${packages[@]}")
      break
    fi
  done
) 9> "$cache/.lock"
version() { node -p "require('$cache/node_modules/$1/package.json').version"; }
echo "@foxglove/schemas $(version @foxglove/schemas), ajv $(version ajv), @mcap/core $(version @mcap/core), node $(node --version)"
"$writer" "$work/sample.mcap" > /dev/null
node "$here/foxglove_schemas.cjs" "$cache" "$work/sample.mcap" --schemas-only | grep -v '^count '
scene=(--procedural --frames 2)
[[ -d $data/kitti/velodyne ]] && scene=(--kitti "$data/kitti" --frames 3)
"$fusedet" synth-log "${scene[@]}" --derived --models "$models" --out "$work/view.mcap" | tee "$work/synth.txt"
node "$here/foxglove_schemas.cjs" "$cache" "$work/view.mcap" | tee "$work/node.txt"
# @mcap/core's counts = fusedet log info's counts, topic by topic.
"$fusedet" log info "$work/view.mcap" | awk '$1 ~ /^\// {print "count", $1, $3}' | sort > "$work/ours.txt"
grep '^count ' "$work/node.txt" | sort > "$work/theirs.txt"
diff "$work/ours.txt" "$work/theirs.txt" && echo "counts agree with fusedet log info: $(wc -l < "$work/ours.txt") topics"
# every synthesised scan decoded again; one tilt sample per TPDO1 the motor simulator sent
scans=$(sed -n 's/^laser *\([0-9]*\) scans.*/\1/p' "$work/synth.txt")
tpdos=$(sed -n 's/.* \([0-9]*\) TPDO1).*/\1/p' "$work/synth.txt")
[[ $(awk '$2 == "/lms291/scan" {print $3}' "$work/theirs.txt") == "$scans" ]] && echo "scans agree: $scans"
[[ $(awk '$2 == "/tilt/sample" {print $3}' "$work/theirs.txt") == "$tpdos" ]] && echo "tilt samples agree: $tpdos"
