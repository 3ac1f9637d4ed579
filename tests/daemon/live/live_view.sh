#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# fusedetd replaying a synthesised sensor log (looping, at recorded speed) with the live view on
# a free loopback port, checked by a real client:
#   client: the official Foxglove WebSocket client and @foxglove/schemas (foxglove_client.cjs)
#   page:   Debian's chromium, headless, driven by puppeteer-core, opens the page at / and checks
#           that the boxes it draws are the detections the Unix socket sends (page_test.cjs);
#           SCREENSHOT (optional) gets a PNG of the page
# The npm packages (@foxglove/ws-protocol, ws, @foxglove/schemas, ajv, puppeteer-core; test tools
# only) are installed into CACHE once (network: the npm registry).
# SCENE: "procedural" (fusedet synth-log --procedural: no KITTI pixels) or "kitti" (KITTI frames
# from DATA/kitti when present, else procedural).
# Usage: live_view.sh client|page FUSEDET FUSEDETD MODELS DATA CACHE WORKDIR SCENE [SCREENSHOT]
set -euo pipefail
mode=$1 fusedet=$2 fusedetd=$3 models=$4 data=$5 cache=$6 work=$7 scene=$8 screenshot=${9:-}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$cache" "$work"
cache=$(cd "$cache" && pwd) work=$(cd "$work" && pwd) models=$(cd "$models" && pwd)
echo "$("$here/../../npm_tools.sh" "$cache" @foxglove/ws-protocol ws @foxglove/schemas ajv puppeteer-core), node $(node --version)"

synth=(--procedural --frames 4)
[[ $scene == kitti && -d $data/kitti/velodyne ]] && synth=(--kitti "$data/kitti" --frames 6)
"$fusedet" synth-log "${synth[@]}" --out "$work/scene.mcap" | head -1
cat > "$work/live.yaml" <<YAML
version: 1
socket: {path: $work/fusedet.sock}
detection: {models: [$(ls "$models"/*.json | paste -sd, -)]}
live: {listen: "127.0.0.1:0", viewer_queue_bytes: 1048576}
replay: {file: $work/scene.mcap, realtime: true, speed: 2.0, at_end: loop}
YAML
: > "$work/fusedetd.log"  # exists before the wait below reads it (the background shell opens it later under load)
"$fusedetd" --config "$work/live.yaml" 2>> "$work/fusedetd.log" &
pid=$!
trap 'kill $pid 2>/dev/null; wait $pid 2>/dev/null || true' EXIT
address=
for _ in $(seq 600); do
  address=$(sed -n 's/.*live view on \(127\.0\.0\.1:[0-9]*\).*/\1/p' "$work/fusedetd.log" | head -1)
  [[ -n $address && -S $work/fusedet.sock ]] && break
  kill -0 $pid 2>/dev/null || { cat "$work/fusedetd.log" >&2; echo "fusedetd ended" >&2; exit 1; }
  sleep 0.1
done
[[ -n $address ]] || { cat "$work/fusedetd.log" >&2; echo "no live view address in fusedetd's log" >&2; exit 1; }
echo "fusedetd live view on $address"
case $mode in
  client) node "$here/foxglove_client.cjs" "$cache" "$address" ;;
  page) node "$here/page_test.cjs" "$cache" "$address" "$work/fusedet.sock" "$work/chromium-profile" "$screenshot" ;;
  *) echo "mode client or page" >&2; exit 2 ;;
esac
